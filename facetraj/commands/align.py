"""``facetraj align``: phone and word labels for a recording, as a Praat TextGrid.

Forced alignment of the sentence (``--text`` / ``--transcript``) or phone recognition
(``--recognize``) with PocketSphinx (``facetraj_engine.labels.alignment``); the label source follows the one rule
of ``facetraj_engine.io.labelling.labels_for_audio``.
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from facetraj_engine.errors import InputError

log = logging.getLogger("facetraj")


def add_label_source_options(p: argparse.ArgumentParser, required: bool = False) -> None:
    """``--text``, ``--transcript``, ``--recognize`` (one of them) and ``--dict``."""
    g = p.add_mutually_exclusive_group(required=required)
    g.add_argument("--text", help="the sentence spoken: its phones are aligned to the audio")
    g.add_argument("--transcript", type=Path, help="a .txt file holding the sentence spoken")
    g.add_argument("--recognize", action="store_true",
                   help="no text: recognize the phones (less accurate than alignment)")
    p.add_argument("--dict", type=Path, metavar="FILE",
                   help="extra pronunciations, CMUdict lines 'WORD  PH1 PH2 ...'")


def add_label_provenance_option(p: argparse.ArgumentParser) -> None:
    """``--label-provenance``: how label files without a record of their own were made."""
    p.add_argument("--label-provenance", choices=["hand-checked", "aligned", "recognized"],
                   help="how label files facetraj did not write were made (default: "
                        "hand-checked; files facetraj wrote record it themselves)")


def extra_dictionary(args: argparse.Namespace) -> dict[str, list[str]] | None:
    from facetraj_engine.labels.alignment import read_dictionary

    return read_dictionary(args.dict) if getattr(args, "dict", None) else None


def cmd_align(args: argparse.Namespace) -> int:
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.io.labelling import labels_for_audio, write_labels

    audio, rate = read_audio(args.audio)
    if args.output.exists() and not args.overwrite:
        raise FileExistsError(f"{args.output}: already exists; choose to overwrite it "
                              "(--overwrite) or give another name")
    labels = labels_for_audio(args.audio, audio, rate, text=args.text, transcript=args.transcript,
                              recognize=args.recognize, extra_dict=extra_dictionary(args))
    if labels is None:
        raise InputError(args.audio, "no sentence to align: give --text, --transcript, or "
                                     "--recognize (or put the sentence in a .txt beside the audio)")
    write_labels(args.output, labels, len(audio) / rate, args.overwrite)
    speech = [p for p in labels.phones if p.label != "sil"]
    log.info("%s: %d phones%s, %s", labels.source, len(speech),
             f" in {len(labels.words)} words" if labels.words else "",
             " ".join(p.label for p in speech))
    print(args.output)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("align", help="phone labels for a recording (alignment or recognition)")
    p.add_argument("audio", type=Path, help="WAV or FLAC, English speech")
    add_label_source_options(p)
    p.add_argument("-o", "--output", type=Path, required=True, help="the .TextGrid to write")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    p.set_defaults(func=cmd_align)
