"""Marker preprocessing (paper section 2.1): gap filling and head-motion removal.

The paper factors head motion out with the markers that do not move with speech (forehead, nose
bridge); here each frame is rigidly fitted (Kabsch) so that its fixed markers best match a
neutral reference pose, and the whole frame is moved with that fit.
"""

from __future__ import annotations

import numpy as np


def fill_gaps(markers: np.ndarray, rate: float, max_gap_s: float = 0.1
              ) -> tuple[np.ndarray, np.ndarray]:
    """Linearly interpolate NaN runs up to ``max_gap_s`` in each marker's trajectory.

    Runs at the start or end are filled with the nearest seen value when short enough. Longer runs
    stay NaN. Returns the filled ``(T, M, 3)`` array and a ``(T,)`` mask of frames where every
    marker is finite afterwards.

    Examples
    --------
    >>> m = np.zeros((5, 1, 3)); m[:, 0, 0] = [0, 1, np.nan, 3, 4]
    >>> filled, valid = fill_gaps(m, rate=60, max_gap_s=0.1)
    >>> filled[:, 0, 0].tolist(), valid.all()
    ([0.0, 1.0, 2.0, 3.0, 4.0], np.True_)
    """
    out = np.array(markers, dtype=np.float64, copy=True)
    n_frames = out.shape[0]
    max_gap = int(np.floor(max_gap_s * rate + 1e-9))
    seen = np.isfinite(out).all(axis=2)  # (T, M)
    t = np.arange(n_frames)
    for m in np.flatnonzero(~seen.all(axis=0)):
        ok = seen[:, m]
        if not ok.any():
            continue
        missing = ~ok
        # lengths of NaN runs
        edges = np.diff(np.concatenate([[0], missing.astype(int), [0]]))
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        fill = np.zeros(n_frames, bool)
        for s, e in zip(starts, ends, strict=True):
            if e - s <= max_gap:
                fill[s:e] = True
        if fill.any():
            for ax in range(3):
                out[fill, m, ax] = np.interp(t[fill], t[ok], out[ok, m, ax])
        out[missing & ~fill, m, :] = np.nan
    valid = np.isfinite(out).all(axis=(1, 2))
    return out, valid


def kabsch(source: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation ``R`` and translation ``t`` minimising ``|| source @ R.T + t - target ||``.

    ``source`` and ``target`` are ``(..., n, 3)``; batched over leading axes. Reflections are
    excluded. Midsagittal (2-D) data, where every x is 0, gets the exact in-plane fit (a rotation
    about x), which needs only two points.

    Examples
    --------
    >>> a = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> rot = np.array([[0., -1, 0], [1, 0, 0], [0, 0, 1]])   # 90 degrees about z
    >>> R, t = kabsch(a @ rot.T + 5, a)
    >>> np.allclose((a @ rot.T + 5) @ R.T + t, a)
    True
    """
    src_c = source.mean(axis=-2, keepdims=True)
    tgt_c = target.mean(axis=-2, keepdims=True)
    if not np.any(source[..., 0]) and not np.any(target[..., 0]):
        return _kabsch_planar(source - src_c, target - tgt_c, src_c, tgt_c)
    h = np.swapaxes(source - src_c, -1, -2) @ (target - tgt_c)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(np.swapaxes(vt, -1, -2) @ np.swapaxes(u, -1, -2)))
    diag = np.ones((*h.shape[:-2], 3))
    diag[..., 2] = np.where(d == 0, 1.0, d)
    rot = np.swapaxes(vt, -1, -2) @ (diag[..., :, None] * np.swapaxes(u, -1, -2))
    trans = tgt_c[..., 0, :] - np.einsum("...ij,...j->...i", rot, src_c[..., 0, :])
    return rot, trans


def _kabsch_planar(src: np.ndarray, tgt: np.ndarray, src_c: np.ndarray, tgt_c: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """In-plane (y-z) rigid fit of centred points; the rotation is about the x axis."""
    y, z = src[..., 1], src[..., 2]
    ty, tz = tgt[..., 1], tgt[..., 2]
    theta = np.arctan2((y * tz - z * ty).sum(-1), (y * ty + z * tz).sum(-1))
    c, s = np.cos(theta), np.sin(theta)
    rot = np.zeros((*theta.shape, 3, 3))
    rot[..., 0, 0] = 1.0
    rot[..., 1, 1], rot[..., 1, 2], rot[..., 2, 1], rot[..., 2, 2] = c, -s, s, c
    trans = tgt_c[..., 0, :] - np.einsum("...ij,...j->...i", rot, src_c[..., 0, :])
    return rot, trans


def remove_head_motion(markers: np.ndarray, fixed: np.ndarray, reference: np.ndarray
                       ) -> np.ndarray:
    """Move every frame rigidly so that its fixed markers best fit ``reference``.

    ``markers`` is ``(T, M, 3)``, ``fixed`` the indices of the fixed markers, ``reference`` their
    ``(len(fixed), 3)`` neutral positions. Frames whose fixed markers are not all finite become NaN.
    No fixed markers (data already head-corrected): the markers as they are.
    """
    markers = np.asarray(markers, dtype=np.float64)
    if len(fixed) == 0:
        return markers.copy()
    src = markers[:, fixed, :]
    ok = np.isfinite(src).all(axis=(1, 2))
    out = np.full_like(markers, np.nan)
    if ok.any():
        rot, trans = kabsch(src[ok], np.broadcast_to(reference, src[ok].shape))
        out[ok] = np.einsum("tij,tmj->tmi", rot, markers[ok]) + trans[:, None, :]
    return out


def reference_pose(frames: np.ndarray, fixed: np.ndarray, iterations: int = 3,
                   block: int = 8192) -> np.ndarray:
    """Neutral pose of the fixed markers: a generalised Procrustes mean of ``frames`` ``(T, M, 3)``.

    Starts from the first complete frame and re-fits every frame to the running mean, ``block``
    frames at a time (what a fit holds stays the same whatever the corpus's length); the mean
    is their sum taken frame after frame, the bits of the mean of all at once. No fixed markers
    (data already head-corrected): an empty pose.
    """
    if len(fixed) == 0:
        return np.zeros((0, 3))
    src = np.asarray(frames, dtype=np.float64)[:, fixed, :]
    src = src[np.isfinite(src).all(axis=(1, 2))]
    if len(src) == 0:
        raise ValueError("no frame has all fixed markers visible")
    ref = src[0]
    for _ in range(iterations):
        total = np.zeros_like(ref)
        for a in range(0, len(src), block):
            part = src[a:a + block]
            rot, trans = kabsch(part, np.broadcast_to(ref, part.shape))
            aligned = np.einsum("tij,tmj->tmi", rot, part) + trans[:, None, :]
            total = np.add.reduce(np.concatenate([total[None], aligned]), axis=0)
        ref = total / len(src)
    return ref
