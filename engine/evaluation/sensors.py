"""Per-sensor scores, as articulatory-inversion papers tabulate them: for every sensor coordinate
(TT y, TB z, LL y, JAW y, ...) the correlation r and the RMSE in mm between the original and the
synthesized trajectory, on the speech frames of section 3, beside the paper's whole face / lower
lip / upper lip correlations (:mod:`facetraj_engine.evaluation.scores`).

Coordinates are facetraj's (mm, the model's head frame): x lateral (right), y up, z forward (the
inversion papers' midsagittal x is z here). A coordinate that does not move in training (a
standard deviation under :data:`STILL_MM`: the x of midsagittal data, a reference sensor's
after head correction) is left out. Per utterance each coordinate is scored on its speech frames where
both trajectories are finite; over utterances r is the mean of the utterances' r (as Table 2
averages them) and the RMSE is pooled over every frame (the root of the mean squared error of
all of them). The **articulators' mean** averages the coordinates of the sensors on the
articulators (not the reference sensors or a palate trace: :attr:`SensorRoles.moving`), as the
papers' "average r" and "average RMSE" do.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass
from typing import Protocol

import numpy as np

from ..method.model import Model
from .correlation import pearson


class Results(Protocol):
    """What the tables read of an :class:`~facetraj_engine.evaluation.scores.EvalResult`."""

    def conditions(self) -> list[tuple[str, str, str, int]]: ...

    def mean(self, split: str, smoothing: str, mode: str = ..., n: int | None = ...
             ) -> dict[str, float]: ...

    def sensor_table(self, split: str, smoothing: str, mode: str = ..., n: int | None = ...
                     ) -> SensorTable: ...

AXES = "xyz"
#: a coordinate whose training standard deviation is below this (mm) does not move: left out
STILL_MM = 0.01


@dataclass(frozen=True)
class CoordinateScore:
    """One sensor coordinate's score: ``r`` and ``rmse_mm`` over ``frames`` frames."""

    sensor: str
    axis: str
    role: str
    r: float
    rmse_mm: float
    frames: int

    @property
    def key(self) -> str:
        """``"TT y"``: the sensor and the coordinate."""
        return f"{self.sensor} {self.axis}"

    def to_json(self) -> dict:
        return {k: (None if isinstance(v, float) and not np.isfinite(v) else v)
                for k, v in asdict(self).items()}


def scored_coordinates(model: Model) -> list[tuple[int, int]]:
    """``(marker, axis)`` of every coordinate that moves in training, in marker order."""
    std = np.asarray(model.coord_std, dtype=np.float64).reshape(model.n_markers, 3)
    return [(m, a) for m in range(model.n_markers) for a in range(3) if std[m, a] > STILL_MM]


def sensor_scores(original: np.ndarray, synthesized: np.ndarray, mask: np.ndarray,
                  model: Model) -> list[CoordinateScore]:
    """Every moving coordinate's r and RMSE (mm) on the frames of ``mask`` where both
    ``(T, M, 3)`` trajectories (head-normalised) are finite.

    >>> from types import SimpleNamespace
    >>> from facetraj_engine.io.sensor_roles import sensor_roles
    >>> m = SimpleNamespace(n_markers=2, coord_std=np.array([0, 1, 1, 0, 1, 0.0]),
    ...                     roles=sensor_roles(["TT", "UL"], 1, 1))
    >>> t = np.linspace(0, 1, 20); o = np.zeros((20, 2, 3)); o[:, 0, 1] = t; o[:, 0, 2] = t ** 2
    >>> s = o + 0.5; s[:, 1, 1] = 2.0
    >>> [(c.key, round(c.r, 3), round(c.rmse_mm, 3)) for c in sensor_scores(o, s, t > 0.2, m)]
    [('TT y', 1.0, 0.5), ('TT z', 1.0, 0.5), ('UL y', nan, 2.0)]
    """
    n = len(mask)
    o, s = np.asarray(original, np.float64)[:n], np.asarray(synthesized, np.float64)[:n]
    roles = model.roles
    out = []
    for m, a in scored_coordinates(model):
        x, y = o[:, m, a], s[:, m, a]
        ok = mask & np.isfinite(x) & np.isfinite(y)
        x, y = x[ok], y[ok]
        rmse = float(np.sqrt(np.mean((y - x) ** 2))) if len(x) else float("nan")
        out.append(CoordinateScore(roles.names[m], AXES[a], roles.role(m), pearson(x, y), rmse,
                                   int(ok.sum())))
    return out


@dataclass(frozen=True)
class SensorTable:
    """Per-sensor scores of one condition over its utterances (module docstring): a row per
    coordinate, and the articulators' mean r and RMSE."""

    rows: list[CoordinateScore]
    mean_r: float
    mean_rmse_mm: float
    utterances: int

    def row(self, key: str) -> CoordinateScore | None:
        """The row of ``"TT y"``, if scored."""
        return next((r for r in self.rows if r.key == key), None)

    def to_json(self) -> dict:
        return {"coordinates": [r.to_json() for r in self.rows],
                "articulators_mean": {"r": _finite(self.mean_r), "rmse_mm": _finite(self.mean_rmse_mm)},
                "utterances": self.utterances}


def _finite(v: float) -> float | None:
    return float(v) if np.isfinite(v) else None


def pooled(per_utterance: Iterable[Sequence[CoordinateScore]]) -> SensorTable:
    """The :class:`SensorTable` of utterances' scores: r averaged over utterances, RMSE pooled
    over their frames; coordinates in the order first seen.

    >>> a = [CoordinateScore("TT", "y", "tongue", 0.8, 1.0, 10)]
    >>> b = [CoordinateScore("TT", "y", "tongue", 0.6, 2.0, 30)]
    >>> t = pooled([a, b]); (round(t.rows[0].r, 3), round(t.rows[0].rmse_mm, 4), t.rows[0].frames)
    (0.7, 1.8028, 40)
    """
    groups: dict[str, list[CoordinateScore]] = {}
    count = 0
    for scores in per_utterance:
        count += 1
        for c in scores:
            groups.setdefault(c.key, []).append(c)
    rows = []
    for cs in groups.values():
        rs = np.array([c.r for c in cs])
        n = np.array([c.frames for c in cs], dtype=np.float64)
        sq = np.array([c.rmse_mm ** 2 if c.frames else 0.0 for c in cs])
        rows.append(CoordinateScore(cs[0].sensor, cs[0].axis, cs[0].role,
                                    float(np.mean(rs[np.isfinite(rs)])) if np.isfinite(rs).any()
                                    else float("nan"),
                                    float(np.sqrt((sq * n).sum() / n.sum())) if n.sum() else float("nan"),
                                    int(n.sum())))
    moving = [r for r in rows if r.role not in ("reference", "palate")]
    rs = np.array([r.r for r in moving])
    es = np.array([r.rmse_mm for r in moving])
    return SensorTable(rows, float(np.mean(rs[np.isfinite(rs)])) if np.isfinite(rs).any() else float("nan"),
                       float(np.mean(es[np.isfinite(es)])) if np.isfinite(es).any() else float("nan"),
                       count)


#: the paper's three correlations, as the per-sensor table's first rows name them
PAPER_ROWS = (("whole face", "whole_face"), ("lower lip y", "lower_lip"), ("upper lip y", "upper_lip"))


@dataclass(frozen=True)
class TableRow:
    """One row of the per-sensor table: a coordinate (``TT y``), one of the paper's three
    correlations (``whole face``, role ``the paper's``: no RMSE) or the articulators' mean; per
    condition its r and RMSE (mm)."""

    name: str
    role: str
    r: list[float]
    rmse_mm: list[float]


def condition_columns(results: Sequence[Results], split: str, smoothing: str = "triangular"
                      ) -> list[tuple[str, SensorTable, dict[str, float]]]:
    """Every condition of ``results`` (the method's, the baselines') on ``split`` with
    ``smoothing``: its name (``phonetic N=3``, ``acoustic N=3``, ``viseme``, ``ridge``), its
    per-sensor table and its three correlations of the paper."""
    out = []
    for result in results:
        for sp, mode, sm, n in result.conditions():
            if (sp, sm) == (split, smoothing):
                name = mode if mode in ("viseme", "ridge") else f"{mode} N={n}"
                out.append((name, result.sensor_table(sp, sm, mode, n), result.mean(sp, sm, mode, n)))
    return out


def table_rows(columns: Sequence[tuple[str, SensorTable, dict[str, float]]]) -> list[TableRow]:
    """The rows of the per-sensor table of ``columns`` (:func:`condition_columns`): the paper's
    three correlations, every coordinate (in the order first seen, the reference sensors' last),
    the articulators' mean."""
    nan = [float("nan")] * len(columns)
    rows = [TableRow(label, "the paper's", [c[2][m] for c in columns], list(nan))
            for label, m in PAPER_ROWS]
    coords = []
    for key in dict.fromkeys(r.key for c in columns for r in c[1].rows):
        cells = [c[1].row(key) for c in columns]
        coords.append(TableRow(key, next(x.role for x in cells if x is not None),
                               [x.r if x else float("nan") for x in cells],
                               [x.rmse_mm if x else float("nan") for x in cells]))
    rows += sorted(coords, key=lambda r: r.role == "reference")     # the references last
    rows.append(TableRow("articulators (mean)", "", [c[1].mean_r for c in columns],
                         [c[1].mean_rmse_mm for c in columns]))
    return rows


def format_sensor_report(results: Sequence[Results], splits: Sequence[str],
                         smoothing: str = "triangular") -> str:
    """Per split, the per-sensor table of every condition side by side (r and RMSE in mm), the
    paper's three correlations in its first rows, as ``facetraj eval`` prints it."""
    blocks = []
    for split in splits:
        cols = condition_columns(results, split, smoothing)
        if not cols:
            continue
        cw = max(14, *(len(c[0]) for c in cols))      # a column: r, a space, RMSE (7)
        lines = [f"Per sensor, {split} split ({smoothing} smoothing; r and RMSE on speech frames):",
                 f"{'sensor':<12} {'role':<10} " + " ".join(f"{c[0]:>{cw}}" for c in cols),
                 f"{'':<23} " + " ".join(f"{'r':>{cw - 8}} {'RMSE mm':>7}" for _ in cols)]
        for row in table_rows(cols):
            head = f"{row.name} (r)" if row.role == "the paper's" else row.name
            head = f"{head:<23}" if row.role in ("the paper's", "") else f"{head:<12} {row.role:<10}"
            lines.append(head + " " + " ".join(f"{_num(r, 3):>{cw - 8}} {_num(e, 2, ''):>7}"
                                               for r, e in zip(row.r, row.rmse_mm, strict=True)))
        blocks.append("\n".join(line.rstrip() for line in lines))
    return "\n\n".join(blocks)


def _num(v: float, digits: int, missing: str = "—") -> str:
    return f"{v:.{digits}f}" if np.isfinite(v) else missing


__all__ = ["PAPER_ROWS", "CoordinateScore", "SensorTable", "TableRow", "condition_columns",
           "format_sensor_report", "pooled", "scored_coordinates", "sensor_scores", "table_rows"]
