"""Speech and pauses by energy (paper section 3): short-time energy, a 112 ms median filter and a
threshold between the utterance's floor and peak. The evaluation scores speech frames only; the
closure step (:mod:`facetraj_engine.method.closure`) rests the face in the long pauses."""

from __future__ import annotations

import functools

import numpy as np

from ..config import EvalConfig
from ..level import peak_scaling
from .quantiles import percentiles


@functools.lru_cache(maxsize=8)
def _squared_window(n: int) -> np.ndarray:
    """``np.hamming(n) ** 2 / n``, made once per length (read-only)."""
    w = np.hamming(n) ** 2 / n
    w.flags.writeable = False
    return w


#: the hops of signal squared and multiplied at a time by :func:`short_time_energy_db` (1 MB of
#: squares, not a copy of the whole signal squared)
ENERGY_CHUNK_HOPS = 2048


def short_time_energy_db(audio: np.ndarray, rate: int, window_s: float = 0.02,
                         hop_s: float = 0.004) -> tuple[np.ndarray, np.ndarray]:
    """Short-time energy in dB and its frame-centre times: frame ``i`` is the ``window_s``
    Hamming-windowed samples from ``i * hop`` of the signal preceded by half a window of zeros,
    its energy the mean of their squares.

    Whatever the signal's gain (issue 38): the squares are those of the signal scaled to a peak
    of 1 (:func:`facetraj_engine.level.peak_scaling`: a sample of 1e200 squared does not overflow),
    so the dB are relative to the peak, with a floor of -120 dB under a silent frame: the same
    recording at any gain has the same energies (to rounding), and the median filter's zero
    padding and the speech/silence threshold see the same values.

    Computed without a copy per frame: the squared signal cut into blocks of one hop, each block
    times the squared window's matching part (a matrix product, :data:`ENERGY_CHUNK_HOPS` blocks
    at a time), and a frame's energy the sum of its window's blocks (the sum of the frames'
    squares to rounding, tested).

    >>> e, t = short_time_energy_db(np.full(16, 0.5), 1000, window_s=0.004, hop_s=0.002)
    >>> e.round(2).tolist()
    [-8.24, -5.23, -5.23, -5.23, -5.23, -5.23, -5.23, -5.23, -8.24]
    >>> bool(np.array_equal(short_time_energy_db(np.full(16, 1e200), 1000, 0.004, 0.002)[0], e))
    True
    >>> (t * 1000).round(6).tolist()
    [0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0]
    """
    x = np.asarray(audio, dtype=np.float64)
    exponent, factor = peak_scaling(x)          # squared after scaling, in the chunks below
    n = max(1, int(round(window_s * rate)))
    hop = max(1, int(round(hop_s * rate)))
    count = len(x) // hop + 1
    blocks = -(-n // hop)                                   # the hops a window spans
    rows = count - 1 + blocks                               # blocks of the padded signal
    w2 = np.zeros(blocks * hop)
    w2[:n] = _squared_window(n)
    w2t = w2.reshape(blocks, hop).T.copy()
    parts = np.empty((rows, blocks))                        # block r times the window's part j
    chunk = np.empty(min(rows, ENERGY_CHUNK_HOPS) * hop)
    for r0 in range(0, rows, ENERGY_CHUNK_HOPS):
        r1 = min(rows, r0 + ENERGY_CHUNK_HOPS)
        a, b = r0 * hop, r1 * hop                           # these blocks' span of the padded signal
        lo = min(max(a, n // 2), b)                         # the signal's part of it: [lo, hi)
        hi = max(lo, min(b, n // 2 + len(x)))
        sq = chunk[:b - a]
        sq[:lo - a] = 0.0
        part = sq[lo - a:hi - a]
        np.ldexp(x[lo - n // 2:hi - n // 2], exponent, out=part)
        part *= factor
        np.square(part, out=part)
        sq[hi - a:] = 0.0
        np.matmul(sq.reshape(-1, hop), w2t, out=parts[r0:r1])
    energy = parts[:count, 0].copy()
    for j in range(1, blocks):
        energy += parts[j:j + count, j]
    return 10 * np.log10(energy + 1e-12), np.arange(count) * hop / rate


#: windows partitioned at a time by :func:`median_filter` (a copy that stays in cache, not one of
#: every window)
MEDIAN_CHUNK = 1024


def median_filter(x: np.ndarray, k: int) -> np.ndarray:
    """Running median of odd length ``k``, zero-padded at both ends (the values of
    ``scipy.signal.medfilt``, tested; here so that the app's first frame does not wait 1-2 s for
    scipy.signal to import).

    >>> median_filter(np.array([3.0, 1.0, 2.0, 5.0, 4.0]), 3).tolist()
    [1.0, 2.0, 2.0, 4.0, 4.0]
    """
    if k % 2 == 0:
        raise ValueError("the median filter length must be odd")
    x = np.asarray(x, dtype=np.float64)
    half = k // 2
    padded = np.concatenate([np.zeros(half), x, np.zeros(half)])
    windows = np.lib.stride_tricks.sliding_window_view(padded, k)
    if not np.isfinite(x).all():                    # NaN: the median of its windows is NaN
        return np.median(windows, axis=1)
    out = np.empty(len(x))                 # the middle value: 8x np.median's speed; a chunk of
    for a in range(0, len(x), MEDIAN_CHUNK):         # windows at a time (its copy stays in cache)
        out[a:a + MEDIAN_CHUNK] = np.partition(windows[a:a + MEDIAN_CHUNK], half, axis=1)[:, half]
    return out


def filtered_energy_db(audio: np.ndarray, rate: int, config: EvalConfig | None = None
                       ) -> np.ndarray:
    """The short-time energy in dB, median-filtered over ``config.median_s`` (112 ms), one value
    per ``config.energy_hop_s``."""
    config = config or EvalConfig()
    e_db, _e_t = short_time_energy_db(audio, rate, config.energy_window_s, config.energy_hop_s)
    k = int(round(config.median_s / config.energy_hop_s))
    k = k + 1 if k % 2 == 0 else k
    return median_filter(e_db, k) if len(e_db) >= k else e_db


def speech_mask(audio: np.ndarray, rate: int, times: np.ndarray,
                config: EvalConfig | None = None, filtered: np.ndarray | None = None) -> np.ndarray:
    """Speech (True) or silence per time in ``times``: energy, 112 ms median filter, threshold
    (``filtered``: :func:`filtered_energy_db` when already computed).

    Examples
    --------
    >>> rate = 16000
    >>> x = np.zeros(rate); x[4000:12000] = np.sin(np.arange(8000) * 0.3)   # 0.25-0.75 s tone
    >>> m = speech_mask(x, rate, np.array([0.1, 0.5, 0.9]))
    >>> m.tolist()
    [False, True, False]
    """
    config = config or EvalConfig()
    if filtered is None:
        filtered = filtered_energy_db(audio, rate, config)
    return _above(filtered, times, config, *percentiles(filtered, [5, 99]))


def _above(filtered: np.ndarray, times: np.ndarray, config: EvalConfig, floor: float,
           peak: float) -> np.ndarray:
    """:func:`speech_mask` from the energy's 5th and 99th percentiles ``floor`` and ``peak``."""
    threshold = floor + config.threshold_fraction * (peak - floor)
    idx = np.round(np.asarray(times) / config.energy_hop_s).astype(int)
    idx = np.minimum(np.maximum(idx, 0), len(filtered) - 1)         # clip, without its checks
    return filtered[idx] > threshold


def speech_runs(mask: np.ndarray, times: np.ndarray, min_s: float = 0.0) -> np.ndarray:
    """``(J, 2)`` ``[start, end)`` times of the runs of True in ``mask`` longer than ``min_s``
    (``times`` the frame times, equally spaced).

    >>> speech_runs(np.array([1, 1, 1, 0, 0, 1], bool), np.arange(6) / 10, 0.25).round(6).tolist()
    [[0.0, 0.3]]
    """
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(np.diff(m.astype(np.int8)))
    step = times[1] - times[0] if len(times) > 1 else 1.0
    runs = [(times[a], times[b - 1] + step) for a, b in zip(edges[::2], edges[1::2], strict=True)]
    return np.array([r for r in runs if r[1] - r[0] > min_s], dtype=np.float64).reshape(-1, 2)


def ranged_speech(audio: np.ndarray, rate: int, times: np.ndarray, min_range_db: float = 20.0,
                  config: EvalConfig | None = None, filtered: np.ndarray | None = None
                  ) -> tuple[np.ndarray, bool]:
    """The speech frames at ``times`` (:func:`speech_mask`) and whether the recording's energy
    spans ``min_range_db`` (99th minus 5th percentile, median-filtered): where it does not, as
    in a recording without a pause, whose quiet speech would pass for one, neither its speech
    nor its silence is told (``filtered``: :func:`filtered_energy_db` when already computed)."""
    if filtered is None:
        filtered = filtered_energy_db(audio, rate, config)
    floor, peak = percentiles(filtered, [5, 99])
    return _above(filtered, times, config or EvalConfig(), floor, peak), bool(peak - floor >= min_range_db)


def silent_frames(audio: np.ndarray, rate: int, times: np.ndarray, min_range_db: float = 20.0,
                  config: EvalConfig | None = None, filtered: np.ndarray | None = None) -> np.ndarray:
    """Whether each frame at ``times`` is silent: not a speech frame, where the energy's range
    tells (:func:`ranged_speech`; else none is).

    >>> rate = 16000
    >>> x = np.zeros(rate); x[4000:12000] = np.sin(np.arange(8000) * 0.3)   # 0.25-0.75 s tone
    >>> t = np.arange(60) / 60
    >>> s = silent_frames(x, rate, t)
    >>> int(s[:15].sum()), int(s[15:46].sum()), int(s[46:].sum())
    (15, 0, 14)
    """
    speech, ranged = ranged_speech(audio, rate, times, min_range_db, config, filtered)
    return ~speech & ranged


def pauses(audio: np.ndarray, rate: int, times: np.ndarray, min_s: float = 0.15,
           min_range_db: float = 20.0, config: EvalConfig | None = None,
           filtered: np.ndarray | None = None) -> np.ndarray:
    """``(J, 2)`` pauses: runs of silent frames (:func:`silent_frames`) longer than ``min_s``.

    >>> rate = 16000
    >>> x = np.zeros(rate); x[4000:12000] = np.sin(np.arange(8000) * 0.3)   # 0.25-0.75 s tone
    >>> t = np.arange(60) / 60
    >>> pauses(x, rate, t).round(2).tolist()
    [[0.0, 0.25], [0.77, 1.0]]
    """
    return speech_runs(silent_frames(audio, rate, times, min_range_db, config, filtered), times, min_s)
