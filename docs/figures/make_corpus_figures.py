"""Draw docs/figures/corpus_markers.png: the 54 markers of the synthetic corpus.

Front and side views of the rest face, coloured by group, with arrows showing how the markers move
when the jaw opens and the lips part (the rig of engine/corpusgen/face.py driven by a VTL-like
open-vowel posture). Run from the repository root::

    python docs/figures/make_corpus_figures.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from facetraj_engine.corpusgen.face import (  # noqa: E402
    GROUPS,
    MARKER_NAMES,
    REST_FACE,
    Drivers,
    FaceConfig,
    articulate,
)

COLORS = ["#555555", "#8c564b", "#2ca02c", "#1f77b4", "#9467bd", "#d62728", "#ff7f0e"]


def open_mouth(cfg: FaceConfig) -> np.ndarray:
    """Marker positions for an open vowel (jaw 3 VTL degrees below rest, lips 1 cm apart)."""
    one = np.ones(1)
    d = Drivers(ja=one * (cfg.rest_ja - 3.0), jx=one * 0.0, lp=one * cfg.rest_lp,
                ld=one * 0.95, ul_y=one * 0.45, ul_x=one * cfg.rest_ul_x, rest=one * 0.0)
    return articulate(d, cfg)[0]


def main(out: Path = ROOT / "docs" / "figures" / "corpus_markers.png") -> Path:
    cfg = FaceConfig()
    rest = REST_FACE
    moved = open_mouth(cfg)
    fig, axes = plt.subplots(1, 2, figsize=(13, 7.5), gridspec_kw={"width_ratios": [1.25, 1]})
    views = [(0, "x (mm) — front view, the talker's right on the left"),
             (2, "z (mm, forward) — side view from the talker's left")]
    for ax, (h, title) in zip(axes, views, strict=True):
        for (group, names), color in zip(GROUPS.items(), COLORS, strict=True):
            idx = [MARKER_NAMES.index(n) for n in names]
            ax.scatter(rest[idx, h], rest[idx, 1], s=36, color=color, label=group, zorder=3,
                       edgecolor="k", linewidth=0.4)
        disp = moved - rest
        big = np.linalg.norm(disp, axis=1) > 0.3
        ax.quiver(rest[big, h], rest[big, 1], 2 * disp[big, h], 2 * disp[big, 1], angles="xy",
                  scale_units="xy", scale=1, color="#d62728", width=0.003, alpha=0.7, zorder=2)
        if h == 0:
            for name, p in zip(MARKER_NAMES, rest, strict=True):
                ax.annotate(name, (p[0], p[1]), fontsize=6.5, xytext=(3, 3),
                            textcoords="offset points")
        ax.set_xlabel(title)
        ax.set_ylabel("y (mm, up)")
        ax.set_aspect("equal")
        ax.set_ylim(-64, 110)
        ax.grid(alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=7, fontsize=8.5, frameon=False)
    axes[0].set_title("54 face markers at rest (origin: where the lips meet)")
    axes[1].set_title("arrows: open vowel vs rest (x2)\njaw about the condyle axis, lips apart")
    axes[1].plot([cfg.condyle_z], [cfg.condyle_y], marker="+", color="k", ms=14)
    axes[1].annotate("condyle axis", (cfg.condyle_z, cfg.condyle_y), xytext=(4, 6),
                     textcoords="offset points", fontsize=8)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


if __name__ == "__main__":
    print(main())
