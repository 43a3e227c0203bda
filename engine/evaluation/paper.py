"""The paper's reference numbers: what the results report and the app's views put beside ours.

Arslan & Talkin, *Speech driven 3-D face point trajectory synthesis* (the longer version in
``../shared/seeds/`` has Tables 1-2). Numbers only, transcribed from the paper; nothing here is
computed from data.
"""

from __future__ import annotations

#: the sentence of the paper's Figure 4
FIGURE4_TEXT = "Tornadoes often destroy acres of farm land"

#: N, the number of context-phones of the paper's Table 2
TABLE2_N = 3

#: the N after which the paper's held-out curve against N levels off (Figure 5)
LEVELS_OFF_AT_N = 3

#: the paper's data (section 3): about 10 minutes of training and 5 of test speech from one
#: talker, 54 face points tracked optically at 60 Hz
TRAIN_MINUTES = 10
TEST_MINUTES = 5
N_MARKERS = 54
MARKER_RATE_HZ = 60

#: the paper's Table 2: (split, smoothing) -> (whole face, lower lip, upper lip), N = 3
PAPER_TABLE2: dict[tuple[str, str], tuple[float, float, float]] = {
    ("train", "triangular"): (0.9239, 0.9463, 0.9287),
    ("train", "spline"): (0.9145, 0.9388, 0.9126),
    ("test", "triangular"): (0.7338, 0.8468, 0.7230),
    ("test", "spline"): (0.6969, 0.7721, 0.7060),
}

#: the paper's Table 1 (top three visually most similar phonemes and their similarity, nu = 10),
#: as printed: ``phone neighbour similarity neighbour similarity neighbour similarity`` entries
#: separated by ``|`` or line ends
PAPER_TABLE1_TEXT = """
aa aw 0.86 hh 0.71 eh 0.70|ae ay 0.94 ey 0.46 aa 0.26|ah dh 0.83 y 0.77 ih 0.75
ao ow 0.62 r 0.24 ah 0.20|aw aa 0.86 hh 0.64 eh 0.64|ax t 0.78 el 0.76 d 0.69
axr uw 0.81 uh 0.72 el 0.69|ay ae 0.94 ey 0.47 aa 0.26|b p 0.78 m 0.58 uw 0.49
ch zh 0.77 sh 0.74 z 0.61|d t 0.88 ih 0.81 dh 0.73|dh ih 0.84 ah 0.83 d 0.73
eh hh 0.94 ey 0.84 aa 0.70|el r 0.81 ax 0.76 uh 0.73|en t 0.75 jh 0.71 ax 0.68
ey eh 0.84 hh 0.77 aa 0.57|f v 0.68 m 0.23 axr 0.18|g l 0.86 iy 0.67 k 0.57
hh eh 0.94 ey 0.77 aa 0.71|ih n 0.92 dh 0.84 d 0.81|iy n 0.83 ng 0.76 l 0.75
jh sh 0.77 en 0.71 z 0.68|k iy 0.70 l 0.60 g 0.57|l g 0.86 iy 0.75 ng 0.62
m p 0.81 b 0.58 uw 0.26|n ih 0.92 ng 0.84 iy 0.83|ng n 0.84 ih 0.77 iy 0.76
ow r 0.65 ao 0.62 el 0.43|p m 0.81 b 0.78 uw 0.46|r el 0.81 uh 0.67 ax 0.67
s z 0.93 sh 0.88 jh 0.60|sh z 0.89 s 0.88 jh 0.77|t d 0.88 ax 0.78 en 0.75
th dh 0.68 ah 0.65 ax 0.59|uh uw 0.76 el 0.73 axr 0.72|uw axr 0.81 uh 0.76 el 0.59
v f 0.68 axr 0.20 m 0.14|w ao 0.12 ow 0.07 r 0.02|y ah 0.77 ih 0.73 n 0.72
z s 0.93 sh 0.89 jh 0.68|zh ch 0.77 sh 0.64 z 0.56
"""


def paper_table1() -> dict[str, list[tuple[str, float]]]:
    """The paper's Table 1 as ``phone -> [(neighbour, similarity)] * 3``.

    Examples
    --------
    >>> t = paper_table1()
    >>> len(t), t["b"]
    (41, [('p', 0.78), ('m', 0.58), ('uw', 0.49)])
    """
    out = {}
    for entry in PAPER_TABLE1_TEXT.replace("\n", "|").split("|"):
        parts = entry.split()
        if parts:
            out[parts[0]] = [(parts[i], float(parts[i + 1])) for i in (1, 3, 5)]
    return out


def table2_value(split: str, smoothing: str) -> tuple[float, float, float]:
    """The paper's Table 2 row (whole face, lower lip, upper lip) of one condition; NaN for a
    condition the paper does not report.

    Examples
    --------
    >>> table2_value("test", "triangular")
    (0.7338, 0.8468, 0.723)
    >>> table2_value("test", "none")
    (nan, nan, nan)
    """
    return PAPER_TABLE2.get((split, smoothing), (float("nan"),) * 3)


__all__ = ["FIGURE4_TEXT", "LEVELS_OFF_AT_N", "MARKER_RATE_HZ", "N_MARKERS", "PAPER_TABLE1_TEXT",
           "PAPER_TABLE2", "TABLE2_N", "TEST_MINUTES", "TRAIN_MINUTES", "paper_table1",
           "table2_value"]
