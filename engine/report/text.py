"""How the report writes numbers: four decimals (or ``n/a``), and a mean with its standard
deviation over utterances."""

from __future__ import annotations

import math

from .rows import ComparisonRow


def fmt(v: float | None, digits: int = 4) -> str:
    """A number with ``digits`` decimals, ``n/a`` when missing or not finite.

    Examples
    --------
    >>> fmt(0.73381), fmt(float("nan")), fmt(2 / 3, 2)
    ('0.7338', 'n/a', '0.67')
    """
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.{digits}f}"


def mean_sd(row: ComparisonRow, metric: str) -> str:
    """``mean ± sd`` of one metric of a row (the ``± sd`` left out when it is not finite)."""
    sd = row.std(metric)
    return fmt(getattr(row, metric)) + (f" ± {sd:.2f}" if sd is not None and math.isfinite(sd) else "")


__all__ = ["fmt", "mean_sd"]
