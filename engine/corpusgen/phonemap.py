"""English ARPAbet phones on VocalTractLab's German speaker JD3.

JD3 knows German SAMPA segments: the vowels ``a e i o u E: 2 y I E O U 9 Y @ 6`` and consonants
by place (labial closure ``p b m``, lower-lip dental fricative ``f v``, tongue-tip dental
fricative ``T D``, alveolar ``t d n s z l``, postalveolar ``S Z tS dZ``, palatal ``j C``, velar
``k g N``, uvular ``R x``, glottal ``h``). Symbols it does not know (``w``, ``r`` as approximant,
English vowels) are silently dropped by VTL, so every ARPAbet phone is mapped here to one or two
JD3 segments. Diphthongs are two vowel targets; ``w`` is a short rounded ``u`` target (a glide);
``er`` is a rounded ``9`` gliding to the vocalic r ``6``.
"""

from __future__ import annotations

from dataclasses import dataclass

#: the 39 ARPAbet phones of the CMU dictionary (stress digits removed)
ARPABET: tuple[str, ...] = (
    "aa", "ae", "ah", "ao", "aw", "ay", "b", "ch", "d", "dh", "eh", "er", "ey", "f", "g", "hh",
    "ih", "iy", "jh", "k", "l", "m", "n", "ng", "ow", "oy", "p", "r", "s", "sh", "t", "th", "uh",
    "uw", "v", "w", "y", "z", "zh",
)

VOWELS: frozenset[str] = frozenset(
    {"aa", "ae", "ah", "ao", "aw", "ay", "eh", "er", "ey", "ih", "iy", "ow", "oy", "uh", "uw"})

#: ARPAbet -> ((JD3 segment, share of the phone's duration), ...); stressed vowels
PHONE_MAP: dict[str, tuple[tuple[str, float], ...]] = {
    # monophthongs
    "aa": (("a", 1.0),),            # father, lot: open /a/
    "ae": (("E:", 1.0),),           # cat: long open-mid front (JD3 has no [æ])
    "ah": (("6", 1.0),),            # strut (stressed): near-open central (VTL's 6_low)
    "ao": (("O", 1.0),),            # thought: open-mid back rounded
    "eh": (("E", 1.0),),            # dress
    "ih": (("I", 1.0),),            # kit
    "iy": (("i", 1.0),),            # fleece
    "uh": (("U", 1.0),),            # foot
    "uw": (("u", 1.0),),            # goose: close back rounded
    "er": (("9", 0.45), ("6", 0.55)),  # nurse: rounded mid vowel gliding to vocalic r
    # diphthongs: two vowel targets
    "aw": (("a", 0.55), ("U", 0.45)),
    "ay": (("a", 0.55), ("I", 0.45)),
    "ey": (("e", 0.6), ("I", 0.4)),
    "ow": (("o", 0.6), ("U", 0.4)),
    "oy": (("O", 0.5), ("I", 0.5)),
    # stops and nasals
    "p": (("p", 1.0),), "b": (("b", 1.0),), "m": (("m", 1.0),),
    "t": (("t", 1.0),), "d": (("d", 1.0),), "n": (("n", 1.0),),
    "k": (("k", 1.0),), "g": (("g", 1.0),), "ng": (("N", 1.0),),
    # fricatives
    "f": (("f", 1.0),), "v": (("v", 1.0),),           # lower lip to the upper teeth
    "th": (("T", 1.0),), "dh": (("D", 1.0),),         # tongue-tip dental fricative
    "s": (("s", 1.0),), "z": (("z", 1.0),),
    "sh": (("S", 1.0),), "zh": (("Z", 1.0),),
    "hh": (("h", 1.0),),
    # affricates
    "ch": (("tS", 1.0),), "jh": (("dZ", 1.0),),
    # approximants
    "l": (("l", 1.0),),
    "r": (("R", 1.0),),             # no English approximant r in JD3: uvular (German) r
    "w": (("u", 1.0),),             # a short rounded close back target = a labial-velar glide
    "y": (("j", 1.0),),             # palatal approximant (VTL voices j like a vowel)
}

#: unstressed variants that differ from the stressed mapping
UNSTRESSED_MAP: dict[str, tuple[tuple[str, float], ...]] = {
    "ah": (("@", 1.0),),            # schwa
    "er": (("6", 1.0),),            # unstressed -er: vocalic r
}


@dataclass(frozen=True)
class Phone:
    """One ARPAbet phone of an utterance (lower case, no stress digit)."""

    label: str
    stress: int | None = None       # 0, 1, 2 for vowels, None for consonants
    word_index: int = -1            # index of its word in the sentence


def split_arpabet(symbol: str) -> tuple[str, int | None]:
    """``'AH0'`` -> ``('ah', 0)``, ``'T'`` -> ``('t', None)``."""
    sym = symbol.strip()
    if sym and sym[-1].isdigit():
        return sym[:-1].lower(), int(sym[-1])
    return sym.lower(), None


def vtl_segments(phone: Phone) -> tuple[tuple[str, float], ...]:
    """The JD3 segments (name, share of the duration) of one ARPAbet phone."""
    if phone.label not in PHONE_MAP:
        raise KeyError(f"no VocalTractLab mapping for ARPAbet phone {phone.label!r}")
    if phone.stress == 0 and phone.label in UNSTRESSED_MAP:
        return UNSTRESSED_MAP[phone.label]
    return PHONE_MAP[phone.label]


def map_table() -> list[tuple[str, str]]:
    """Rows ``(arpabet, 'jd3 segments')`` for the documentation."""
    rows = []
    for p in ARPABET:
        main = " + ".join(f"{s}" if f == 1.0 else f"{s} ({f:.0%})" for s, f in PHONE_MAP[p])
        if p in UNSTRESSED_MAP:
            alt = " + ".join(s for s, _ in UNSTRESSED_MAP[p])
            main += f"; unstressed: {alt}"
        rows.append((p, main))
    return rows
