"""Which articulograph sensor is which articulator: tongue (tip to rear), lips, jaw, palate,
velum and the head-correction's reference sensors, from the sensors' names.

The names of the usual conventions are known (case and ``_``/``-``/space separators ignored):

========== ==================================================================================
tongue     tip: TT TTIP TIP TONGUETIP; blade: TBL TBLADE TF; body: TB TM TMID TBODY TONGUEBODY;
           rear: TD TR TBACK TREAR TDORSUM TONGUEBACK TONGUEDORSUM; numbered T1 T2 T3 ... (T1 the
           tip: XRMB, mngu0). HPRC: TT TB TR; MOCHA-TIMIT: TT TB TD; Carstens/VisArtico: TTIP
           TMID TBACK or TT TM TD.
lips       the corpus's ``upper_lip`` and ``lower_lip``; corners: the corpus's ``lip_corners``,
           else ML MR LC RC LCL LCR LIPL LIPR (HPRC's ML, the mouth's left corner)
jaw        JAW LI MNI MAND LOWERINCISOR first (the sensor on the lower incisors), then JAWL JAWR
           MNM (HPRC's JAWL, XRMB's molar pellet)
palate     PAL PALATE PALATETRACE: a palate trace, drawn as the line of every position it took
velum      V VEL VELUM (MOCHA's V)
reference  the corpus's fixed markers, and UI UPPERINCISOR BN NB NOSE NASION REF REF1 ... LMA
           RMA LMAST RMAST LEAR REAR HEAD (MOCHA's UI and BN; NDI's REF; mastoids, ears)
========== ==================================================================================

A marker set with a tongue sensor is an **articulograph** set (the app draws it as articulators,
not as a face). ``corpus.json``'s ``sensor_roles`` overrides the names: an object of role lists,
``{"tongue": ["T3", "T2", "T1"], "reference": ["LMA", "RMA"], "jaw": ["LI"]}`` (the tongue tip
first); a sensor named under a role has that role only; ``{"tongue": []}`` says a set has no tongue
(a face). The roles ``tongue jaw palate velum reference other`` (``other``: drawn as a plain
point). The rule is one function, :func:`sensor_roles`; docs/app.md says it in words.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

#: the roles ``corpus.json``'s ``sensor_roles`` may name
OVERRIDE_ROLES = ("tongue", "jaw", "palate", "velum", "reference", "other")

TONGUE_NAMES = {**dict.fromkeys(("TT", "TTIP", "TIP", "TONGUETIP"), 0),
                **dict.fromkeys(("TBL", "TBLADE", "TF"), 1),
                **dict.fromkeys(("TB", "TM", "TMID", "TBODY", "TONGUEBODY", "TONGUEMID"), 2),
                **dict.fromkeys(("TD", "TR", "TBACK", "TREAR", "TDORSUM", "TONGUEBACK",
                                 "TONGUEDORSUM", "TONGUEREAR"), 3)}
CORNER_NAMES = ("ML", "MR", "LC", "RC", "LCL", "LCR", "LIPL", "LIPR")
JAW_MAIN = ("JAW", "LI", "MNI", "MAND", "LOWERINCISOR")
JAW_OTHER = ("JAWL", "JAWR", "MNM", "JAWLEFT", "JAWRIGHT")
PALATE_NAMES = ("PAL", "PALATE", "PALATETRACE")
VELUM_NAMES = ("V", "VEL", "VELUM")
REFERENCE_NAMES = ("UI", "UPPERINCISOR", "BN", "NB", "NOSE", "NASION", "REF", "LMA", "RMA",
                   "LMAST", "RMAST", "LEAR", "REAR", "HEAD")


def _key(name: str) -> str:
    """A name as the tables spell it: upper case, no separators.

    >>> _key("tongue_tip"), _key("T-3"), _key("jaw l")
    ('TONGUETIP', 'T3', 'JAWL')
    """
    return re.sub(r"[\s_\-.]", "", name).upper()


def tongue_rank(name: str) -> float | None:
    """Where a tongue sensor sits, tip (0) to rear; ``None`` for a name that is no tongue's.

    >>> tongue_rank("TT"), tongue_rank("TR"), tongue_rank("T2"), tongue_rank("UL")
    (0, 3, 1, None)
    """
    key = _key(name)
    if key in TONGUE_NAMES:
        return TONGUE_NAMES[key]
    hit = re.fullmatch(r"T(\d)", key)
    return int(hit.group(1)) - 1 if hit else None


def _named(names: Sequence[str], table: Sequence[str]) -> list[int]:
    """Indices of ``names`` found in ``table``, in the table's order."""
    keys = [_key(n) for n in names]
    return [keys.index(t) for t in table if t in keys]


@dataclass(frozen=True)
class SensorRoles:
    """The articulators among a marker set's ``names`` (indices into them): ``tongue`` tip to
    rear, the lip centres and corners, ``jaw`` (the lower-incisor sensor first), ``palate``,
    ``velum``, ``reference`` (head-correction sensors); the rest are ``other``."""

    names: tuple[str, ...]
    tongue: tuple[int, ...]
    upper_lip: int
    lower_lip: int
    lip_corners: tuple[int, ...] = ()
    jaw: tuple[int, ...] = ()
    palate: tuple[int, ...] = ()
    velum: tuple[int, ...] = ()
    reference: tuple[int, ...] = ()

    @property
    def articulograph(self) -> bool:
        """Whether the set is articulograph sensors (it has a tongue), not a face."""
        return bool(self.tongue)

    def role(self, i: int) -> str:
        """The role of marker ``i``: tongue, upper lip, lower lip, lip corner, jaw, palate,
        velum, reference or other."""
        if i == self.upper_lip:
            return "upper lip"
        if i == self.lower_lip:
            return "lower lip"
        for role in ("tongue", "lip_corners", "jaw", "palate", "velum", "reference"):
            if i in getattr(self, role):
                return {"lip_corners": "lip corner"}.get(role, role)
        return "other"

    @property
    def moving(self) -> tuple[int, ...]:
        """The sensors on the articulators: all but the reference sensors and the palate trace."""
        still = set(self.reference) | set(self.palate)
        return tuple(i for i in range(len(self.names)) if i not in still)


def sensor_roles(names: Sequence[str], upper_lip: int, lower_lip: int,
                 lip_corners: Sequence[int] = (), fixed: Sequence[int] = (),
                 overrides: Mapping[str, Sequence[str]] | None = None) -> SensorRoles:
    """The roles of ``names`` (module docstring): the lips and fixed markers as the corpus names
    them, the rest by the naming conventions, ``overrides`` (``corpus.json``'s
    ``sensor_roles``) over both.

    >>> r = sensor_roles(["TR", "TB", "TT", "UL", "LL", "ML", "JAW", "JAWL"], 3, 4)
    >>> r.articulograph, [r.names[i] for i in r.tongue], [r.names[i] for i in r.jaw], r.lip_corners
    (True, ['TT', 'TB', 'TR'], ['JAW', 'JAWL'], (5,))
    >>> r = sensor_roles(["UI", "LI", "UL", "LL", "TT", "TB", "TD", "V", "BN"], 2, 3, fixed=[0, 8])
    >>> [r.role(i) for i in range(9)]
    ['reference', 'jaw', 'upper lip', 'lower lip', 'tongue', 'tongue', 'tongue', 'velum', 'reference']
    >>> sensor_roles(["A", "B", "C"], 0, 1, overrides={"tongue": ["C"]}).tongue
    (2,)
    """
    names = list(names)
    lips = {upper_lip, lower_lip}
    tongue = sorted((i for i, n in enumerate(names) if tongue_rank(n) is not None and i not in lips),
                    key=lambda i: (tongue_rank(names[i]), i))
    corners = list(lip_corners) or [i for i in _named(names, CORNER_NAMES) if i not in lips]
    roles = {"tongue": tongue, "lip_corners": corners,
             "jaw": _named(names, JAW_MAIN) + _named(names, JAW_OTHER),
             "palate": _named(names, PALATE_NAMES), "velum": _named(names, VELUM_NAMES),
             "reference": sorted(set(fixed) | set(_named(names, REFERENCE_NAMES)))}
    for role, given in (overrides or {}).items():
        picked = [names.index(n) for n in given]
        roles = {r: [i for i in v if i not in picked] for r, v in roles.items()}
        if role != "other":
            roles[role] = picked
    taken: set[int] = set(lips)
    for role in ("tongue", "lip_corners", "jaw", "palate", "velum", "reference"):
        roles[role] = [i for i in roles[role] if i not in taken]
        taken |= set(roles[role])
    return SensorRoles(tuple(names), tuple(roles["tongue"]), upper_lip, lower_lip,
                       tuple(roles["lip_corners"]), tuple(roles["jaw"]), tuple(roles["palate"]),
                       tuple(roles["velum"]), tuple(roles["reference"]))


def overrides_problem(overrides: object, names: Sequence[str]) -> str | None:
    """What is wrong with a ``sensor_roles`` object for the markers ``names`` (``None``: nothing).

    >>> overrides_problem({"tongue": ["TT", "XX"]}, ["TT", "UL"])
    "'sensor_roles' names 'XX', not among marker_names"
    >>> overrides_problem({"teeth": ["TT"]}, ["TT"])
    "'sensor_roles' has the role 'teeth', not one of tongue jaw palate velum reference other"
    """
    if not isinstance(overrides, dict):
        return f"'sensor_roles' is {type(overrides).__name__}, not an object of role lists"
    seen: set[str] = set()
    for role, given in overrides.items():
        if role not in OVERRIDE_ROLES:
            return f"'sensor_roles' has the role {role!r:.40}, not one of {' '.join(OVERRIDE_ROLES)}"
        if not isinstance(given, list) or not all(isinstance(n, str) for n in given):
            return f"'sensor_roles' {role!r} is not a list of marker names"
        for n in given:
            if n not in names:
                return f"'sensor_roles' names {n!r:.40}, not among marker_names"
            if n in seen:
                return f"'sensor_roles' gives {n!r:.40} two roles"
            seen.add(n)
    return None


__all__ = ["OVERRIDE_ROLES", "SensorRoles", "overrides_problem", "sensor_roles", "tongue_rank"]
