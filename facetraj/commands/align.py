"""``facetraj align``: phone and word labels for a recording, as a Praat TextGrid.

Forced alignment of the sentence (``--text`` / ``--transcript``) or phone recognition
(``--recognize``) with PocketSphinx (``facetraj_engine.labels.alignment``); the label source follows the one
rule
of ``facetraj_engine.io.label_rule.resolve_labels``.
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


def add_label_options(p: argparse.ArgumentParser) -> None:
    """Every option of where a recording's labels come from (the one rule,
    ``facetraj_engine.io.label_rule.resolve_labels``): ``--labels``, ``--text`` / ``--transcript`` /
    ``--recognize``, ``--dict``, ``--label-map``, ``--label-provenance``; and
    ``--read-damaged-audio``."""
    p.add_argument("--labels", type=Path, help="phone labels: .TextGrid, .lab or .phn (default: "
                   "one beside the audio, else the sentence of a .txt beside it, aligned, else "
                   "the phones recognized; --mode acoustic: none)")
    add_label_source_options(p)
    p.add_argument("--label-map", metavar="FILE|ALPHABET",
                   help="map the labels onto ARPAbet with this label map (TSV: label<TAB>arpabet) "
                        "or alphabet (mocha, timit, sampa, x-sampa, ipa); without it a label "
                        "file's alphabet is recognised (docs/labels.md)")
    add_label_provenance_option(p)
    add_damaged_audio_option(p)


def add_damaged_audio_option(p: argparse.ArgumentParser) -> None:
    """``--read-damaged-audio``: read an audio file whose header does not match its data."""
    p.add_argument("--read-damaged-audio", action="store_true",
                   help="read an audio file cut short or whose header does not match its data, "
                        "as it is (refused by default: docs/bad-input.md)")


def label_request(args: argparse.Namespace, fallback: bool = True):
    """The :class:`~facetraj_engine.io.label_rule.LabelRequest` of the label options given."""
    from facetraj_engine.io.label_rule import LabelRequest

    return LabelRequest(labels=getattr(args, "labels", None), text=args.text,
                        transcript=args.transcript, recognize=args.recognize,
                        declared=getattr(args, "label_provenance", None),
                        label_map=getattr(args, "label_map", None),
                        extra_dict=extra_dictionary(args), fallback=fallback)


def extra_dictionary(args: argparse.Namespace) -> dict[str, list[str]] | None:
    from facetraj_engine.labels.alignment import read_dictionary

    return read_dictionary(args.dict) if getattr(args, "dict", None) else None


def cmd_align(args: argparse.Namespace) -> int:
    from facetraj_engine.io.audio import read_audio
    from facetraj_engine.io.files import check_output_path
    from facetraj_engine.io.label_rule import resolve_labels
    from facetraj_engine.io.labelling import write_labels

    check_output_path(args.output, args.overwrite, (".textgrid",), probe=True)   # before the work
    audio, rate = read_audio(args.audio, args.read_damaged_audio)
    found = resolve_labels(args.audio, audio, rate, label_request(args, fallback=False))
    labels = found.labels
    if labels is None:
        raise InputError(args.audio, "no sentence to align: give --text, --transcript, or "
                                     "--recognize (or put the sentence in a .txt beside the audio)")
    write_labels(args.output, labels, len(audio) / rate, args.overwrite)
    speech = [p for p in labels.phones if p.label != "sil"]
    log.info("%s: labels %s", args.audio.name, found.describe())
    log.info("%s: %d phones%s, %s", labels.source, len(speech),
             f" in {len(labels.words)} words" if labels.words else "",
             " ".join(p.label for p in speech))
    print(args.output)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("align", help="phone labels for a recording (alignment or recognition)")
    p.add_argument("audio", type=Path, help="WAV or FLAC, English speech")
    add_label_source_options(p)
    add_damaged_audio_option(p)
    p.add_argument("-o", "--output", type=Path, required=True, help="the .TextGrid to write")
    p.add_argument("--overwrite", action="store_true", help="replace an existing file")
    p.set_defaults(func=cmd_align)
