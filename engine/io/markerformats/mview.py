"""MVIEW ``.mat`` files (Mark Tiede's MVIEW tools: Haskins, HPRC and many labs).

One MATLAB struct array (named after the file, by convention) with one element per channel:
``NAME``, ``SRATE`` (Hz) and ``SIGNAL``: the audio first (a column), then the sensors, ``N x 3``
(x forward, y lateral, z up, mm; ``N x 6`` or ``N x 7`` add orientations, not used; ``N x 2`` is
midsagittal x, z). The audio channel often carries ``PHONES`` and ``WORDS`` (struct arrays of
``LABEL`` and ``OFFS``: start and end in seconds) and ``SENTENCE``. MVIEW data is head-corrected
by convention. Files of MATLAB v5-v7 are read with ``scipy.io.loadmat``, v7.3 files (HDF5) with
h5py. Sensors of other rates are resampled to the fastest one; NaN samples are missing. Axes:
MVIEW's x, y, z become facetraj's z, x, y.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from ...data import PhoneSegment
from ...errors import InputError
from .common import check_rate, mark_missing, read_binary, resample_markers
from .recording import MarkerRecording, midsagittal
from .registry import MarkerFormat

log = logging.getLogger(__name__)

MAGIC = b"MATLAB "
HDF5_AT_512 = b"\x89HDF\r\n\x1a\n"
#: Audio rates read (Hz).
AUDIO_RATES = (8000, 384000)


def read_mview(path: Path) -> MarkerRecording:
    """Read an MVIEW ``.mat`` file (see the module's description)."""
    raw = read_binary(path, "MATLAB file")
    if raw[512:520] == HDF5_AT_512 or raw.startswith((HDF5_AT_512, b"MATLAB 7.3")):
        from .mview_h5 import variables_v73

        entries = pick_struct(path, variables_v73(path))
    else:
        entries = _entries_v5(path)
    return _recording(path, entries)


def _entries_v5(path: Path) -> list[dict]:
    """The elements of the file's MVIEW struct array, as dicts (MATLAB v5-v7)."""
    from scipy.io import loadmat

    try:
        mat = loadmat(path, simplify_cells=True)
    except Exception as exc:  # scipy raises many kinds on a damaged file
        raise InputError(path, f"not a readable MATLAB file ({str(exc).splitlines()[0][:120]})"
                         ) from None
    variables = {k: v for k, v in mat.items() if not k.startswith("__")}
    return pick_struct(path, variables)


def pick_struct(path: Path, variables: dict) -> list[dict]:
    """The MVIEW struct array among a file's variables: the one named after the file, else the
    first with NAME, SRATE and SIGNAL."""
    def elements(value) -> list[dict] | None:
        items = [value] if isinstance(value, dict) else value
        if isinstance(items, (list, np.ndarray)) and len(items) and all(
                isinstance(e, dict) and {"NAME", "SRATE", "SIGNAL"} <= set(e) for e in items):
            return list(items)
        return None

    order = sorted(variables, key=lambda k: k != path.stem)
    for name in order:
        found = elements(variables[name])
        if found:
            return found
    raise InputError(path, f"no MVIEW struct array (NAME, SRATE, SIGNAL per channel) among its "
                           f"variables ({', '.join(variables)[:80] or 'none'})")


def _text(value) -> str:
    if isinstance(value, str):
        return value.strip()
    if isinstance(value, np.ndarray) and value.dtype.kind == "U":
        return "".join(value.ravel()).strip()
    return ""


def _rate(path: Path, entry: dict) -> float:
    try:
        return float(np.asarray(entry["SRATE"], dtype=np.float64).ravel()[0])
    except (TypeError, ValueError, IndexError):
        raise InputError(path, f"channel {_text(entry.get('NAME'))!r}: SRATE is not a number") from None


def _signal(path: Path, entry: dict) -> np.ndarray:
    signal = entry["SIGNAL"]
    if not isinstance(signal, np.ndarray) or signal.dtype.kind not in "iuf":
        raise InputError(path, f"channel {_text(entry.get('NAME'))!r}: SIGNAL is not numeric")
    return signal


def _channels(path: Path, entries: list[dict]) -> tuple[dict | None, list[dict]]:
    """The audio channel (a column) and the sensor channels (2 or more columns)."""
    audio, sensors = None, []
    for entry in entries:
        signal = _signal(path, entry)
        if signal.ndim == 1 or (signal.ndim == 2 and 1 in signal.shape):
            if audio is None and _rate(path, entry) >= AUDIO_RATES[0]:
                audio = entry
        elif signal.ndim == 2 and signal.shape[1] >= 2:
            sensors.append(entry)
        else:
            log.info("%s: channel %r (SIGNAL %s) left out", path.name, _text(entry.get("NAME")),
                     signal.shape)
    if not sensors:
        raise InputError(path, "no sensor channel (a SIGNAL of N x 2, 3, 6 or 7) in the MVIEW struct")
    return audio, sensors


def _positions(path: Path, sensors: list[dict]) -> tuple[np.ndarray, float]:
    """The sensors as ``(frames, sensors, 3)`` in facetraj's axes at the fastest sensor rate."""
    rates = [check_rate(path, _rate(path, e), f" of {_text(e.get('NAME'))!r}") for e in sensors]
    rate = max(rates)
    tracks = []
    for entry, r in zip(sensors, rates, strict=True):
        sig = np.asarray(entry["SIGNAL"], dtype=np.float64)
        pos = midsagittal(sig[:, 0], sig[:, 1]) if sig.shape[1] == 2 else sig[:, [1, 2, 0]]
        tracks.append(resample_markers(pos[:, None, :], r, rate)[:, 0] if r != rate else pos)
    frames = max(len(t) for t in tracks)
    markers = np.full((frames, len(tracks), 3), np.nan)
    for i, track in enumerate(tracks):
        markers[:len(track), i] = track
    return markers, rate


def _segments(value) -> list[PhoneSegment]:
    """PHONES or WORDS (``LABEL`` and ``OFFS`` = [start end] s per element) as segments."""
    items = [value] if isinstance(value, dict) else value
    if not isinstance(items, (list, np.ndarray)):
        return []
    out = []
    for item in items:
        if not isinstance(item, dict) or "OFFS" not in item:
            continue
        offs = np.asarray(item["OFFS"], dtype=np.float64).ravel()
        if offs.size >= 2 and np.isfinite(offs[:2]).all():
            out.append(PhoneSegment(float(offs[0]), float(offs[1]), _text(item.get("LABEL")) or "sil"))
    return sorted(out, key=lambda s: s.start)


def _audio(path: Path, entry: dict) -> tuple[np.ndarray, int]:
    rate = int(round(_rate(path, entry)))
    if not AUDIO_RATES[0] <= rate <= AUDIO_RATES[1]:
        raise InputError(path, f"the audio channel's SRATE {rate} Hz is outside "
                               f"{AUDIO_RATES[0]}-{AUDIO_RATES[1]} Hz")
    signal = np.asarray(entry["SIGNAL"]).ravel()
    if signal.dtype.kind in "iu":
        samples = signal.astype(np.float64) / float(np.iinfo(signal.dtype).max)
    else:
        samples = signal.astype(np.float64)
    if not np.isfinite(samples).all() or len(samples) < rate // 100:
        raise InputError(path, "the audio channel holds NaN or less than 10 ms")
    return samples, rate


def _recording(path: Path, entries: list[dict]) -> MarkerRecording:
    audio_entry, sensors = _channels(path, entries)
    markers, rate = _positions(path, sensors)
    names = [_text(e.get("NAME")) or f"Ch{i + 1}" for i, e in enumerate(sensors)]
    if len(set(names)) != len(names):
        raise InputError(path, f"two sensor channels share a NAME ({' '.join(names)})")
    rec = MarkerRecording(markers, rate, names, head_corrected=True)
    rec.missing = mark_missing(path, markers, ~np.isfinite(markers).all(axis=2), "NaN in SIGNAL")
    labelled = [e for e in ([audio_entry] if audio_entry else []) + entries if "PHONES" in e]
    if audio_entry is not None:
        rec.audio, rec.audio_rate = _audio(path, audio_entry)
    if labelled:
        rec.phones = _segments(labelled[0]["PHONES"])
        rec.words = [w for w in _segments(labelled[0].get("WORDS", [])) if w.label != "sil"]
    rec.transcript = next((_text(e.get("SENTENCE")) for e in entries if _text(e.get("SENTENCE"))), "")
    return rec


FORMATS = (MarkerFormat("MVIEW", (".mat",), read_mview, sniff=lambda head: head.startswith(MAGIC),
                        signature="MATLAB v5-v7.3 file", carries_audio=True, carries_labels=True,
                        order=50),)
