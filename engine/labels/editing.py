"""Labels corrected by hand, one edit at a time: the phones and words of one recording as a
phonetician edits them (in the app's timeline), without any GUI.

A :class:`LabelDocument` holds the two tiers, the segment selected, and the edits made, each an
:class:`Edit` that names what it did (``rename /n/ → /m/``) and can be undone and redone. Every
edit is checked before anything changes and refused with a one-line :class:`EditRefused` that
says why: a phone the model does not know, a boundary that would cross its neighbour, a split
outside the segment. Boundaries land on the model's frames (``frame_rate``: a boundary between
two frames changes nothing the synthesis sees) and a word's edges carry the phone boundaries that
lie on them.

The phones a person changed are told exactly as a TextGrid read back tells them
(:func:`facetraj_engine.labels.provenance.labels_from_tiers`): a phone of automatic labels that
no longer matches the ``confidence`` interval its maker recorded is checked by hand, the others
keep their maker's confidence. :meth:`LabelDocument.labels` are the labels on screen as
``facetraj synth`` reads them once saved (``facetraj_engine.io.labelling.write_labels``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from ..data import PhoneSegment, Provenance
from .phoneset import ARPABET, SILENCE, SILENCE_LABELS, normalise_label
from .provenance import CONFIDENCE_TIER, PROVENANCE_TIER, Labels, labels_from_tiers, provenance_text

#: the tiers a document edits
PHONES, WORDS = "phones", "words"
#: times closer than this (s) are the same time (as a TextGrid read back tells them)
SAME_S = 5e-4


class EditRefused(ValueError):
    """An edit that cannot be made, and why (one line); nothing was changed."""


@dataclass(frozen=True)
class Tiers:
    """The phones and the words of a recording at one moment (immutable: an edit makes new
    ones, so that undo is a step back to the tiers kept)."""

    phones: tuple[PhoneSegment, ...]
    words: tuple[PhoneSegment, ...] = ()


@dataclass(frozen=True)
class Selection:
    """A segment picked: its tier (``phones`` or ``words``) and its index in it."""

    tier: str
    index: int


@dataclass(frozen=True)
class Edit:
    """One edit: what it did in words (``rename /n/ → /m/ at 1.100 s``), the tiers before and
    after it and the selection before and after it."""

    description: str
    before: Tiers
    after: Tiers
    selected_before: Selection | None = None
    selected_after: Selection | None = None


def shown(label: str) -> str:
    """A label as the edits name it: a phone between slashes, silence as it is.

    >>> shown("m"), shown("sil")
    ('/m/', 'silence')
    """
    return "silence" if label == SILENCE else f"/{label}/"


@dataclass
class LabelDocument:
    """The labels of one recording being corrected.

    ``labels``: as they were made or read (their source, provenance, confidence and the phones
    already checked by hand); ``duration``: the recording's (s); ``frame_rate``: the frames
    boundaries snap to (the model's marker rate); ``phone_set``: the phones a phone may be
    renamed to (the model's; ``None``: ARPAbet), silence always. ``name`` names the recording
    in messages."""

    labels: Labels
    duration: float
    frame_rate: float = 60.0
    phone_set: Sequence[str] | None = None
    name: str = ""
    tiers: Tiers = field(init=False)
    selection: Selection | None = field(default=None, init=False)
    history: list[Edit] = field(default_factory=list, init=False)
    done: int = field(default=0, init=False)         # edits in effect (the rest can be redone)
    saved_at: int | None = field(default=0, init=False)   # ``done`` when last saved (None: never)

    def __post_init__(self) -> None:
        self.tiers = Tiers(tuple(self.labels.phones), tuple(self.labels.words))
        known = self.phone_set if self.phone_set is not None else ARPABET
        self.known = frozenset(normalise_label(p) for p in known) | {SILENCE}
        made = self.labels
        hand = made.hand_checked
        # the confidence tier as its maker wrote it (full precision here; three decimals in a file)
        self.record = [PhoneSegment(s.start, s.end, f"{s.label} {float(c)!r}" if np.isfinite(c)
                                    else f"{s.label} -")
                       for s, c, h in zip(made.phones, made.confidence, hand, strict=True) if not h]

    # ------------------------------------------------------------------ state
    @property
    def phones(self) -> tuple[PhoneSegment, ...]:
        return self.tiers.phones

    @property
    def words(self) -> tuple[PhoneSegment, ...]:
        return self.tiers.words

    def segments(self, tier: str) -> tuple[PhoneSegment, ...]:
        return self.tiers.phones if tier == PHONES else self.tiers.words

    @property
    def dirty(self) -> bool:
        """Whether the tiers differ from the last saved (or, never saved, the first) ones."""
        return self.saved_at != self.done

    @property
    def edited(self) -> bool:
        """Whether any edit is in effect (the labels differ from those made)."""
        return self.done > 0

    def mark_saved(self) -> None:
        self.saved_at = self.done

    @property
    def undo_text(self) -> str:
        """What undo would undo (``""``: nothing)."""
        return self.history[self.done - 1].description if self.done else ""

    @property
    def redo_text(self) -> str:
        return self.history[self.done].description if self.done < len(self.history) else ""

    def labels_now(self) -> Labels:
        """The labels on screen as they read back once saved: automatic labels keep their source,
        provenance and each unchanged phone's confidence, and every phone changed counts as
        checked by hand (:func:`~facetraj_engine.labels.provenance.labels_from_tiers`, the
        reader's own rule); hand-checked labels stay hand-checked."""
        made = self.labels
        phones, words = list(self.tiers.phones), list(self.tiers.words)
        if made.provenance.hand_checked:
            return Labels(phones, words, made.source, provenance=made.provenance, text=made.text)
        record = {PROVENANCE_TIER: [PhoneSegment(0.0, self.duration, provenance_text(made.provenance))],
                  CONFIDENCE_TIER: self.record}
        read = labels_from_tiers(phones, words, record)
        p = made.provenance
        return replace(read, source=made.source, text=made.text,
                       provenance=Provenance(p.kind, p.tool, p.origin, read.provenance.corrected, p.why))

    def changed(self) -> np.ndarray:
        """Per phone, whether it counts as checked by hand (changed here, or before)."""
        return self.labels_now().hand_checked

    # ------------------------------------------------------------------ undo
    def _apply(self, description: str, tiers: Tiers, selection: Selection | None) -> Edit:
        edit = Edit(description, self.tiers, tiers, self.selection, selection)
        del self.history[self.done:]
        if self.saved_at is not None and self.saved_at > self.done:
            self.saved_at = None                 # the saved state can no longer be reached
        self.history.append(edit)
        self.done += 1
        self.tiers, self.selection = tiers, selection
        return edit

    def undo(self) -> Edit:
        """Undo the last edit in effect (:class:`EditRefused` when there is none)."""
        if not self.done:
            raise EditRefused("nothing to undo")
        self.done -= 1
        edit = self.history[self.done]
        self.tiers, self.selection = edit.before, edit.selected_before
        return edit

    def redo(self) -> Edit:
        if self.done >= len(self.history):
            raise EditRefused("nothing to redo")
        edit = self.history[self.done]
        self.done += 1
        self.tiers, self.selection = edit.after, edit.selected_after
        return edit

    # ------------------------------------------------------------------ selection
    def select(self, tier: str, index: int | None) -> Selection | None:
        """Pick segment ``index`` of ``tier`` (``None``: nothing)."""
        if index is None:
            self.selection = None
        else:
            self._segment(tier, index)
            self.selection = Selection(tier, index)
        return self.selection

    def select_at(self, tier: str, t: float) -> Selection | None:
        """Pick the segment of ``tier`` at ``t`` seconds (nothing where the words tier has none)."""
        return self.select(tier, self.index_at(tier, t))

    def index_at(self, tier: str, t: float) -> int | None:
        segs = self.segments(tier)
        for i, s in enumerate(segs):
            if s.start <= t < s.end or (i == len(segs) - 1 and t == s.end):
                return i
        return None

    def step_selection(self, direction: int) -> Selection | None:
        """Pick the next (``direction`` > 0) or previous segment of the selected tier."""
        sel = self.selection
        if sel is None:
            return self.select(PHONES, 0) if self.phones else None
        n = len(self.segments(sel.tier))
        return self.select(sel.tier, min(max(sel.index + (1 if direction > 0 else -1), 0), n - 1))

    def _segment(self, tier: str, index: int) -> PhoneSegment:
        segs = self.segments(tier)
        if tier not in (PHONES, WORDS):
            raise EditRefused(f"no tier {tier!r} (phones or words)")
        if not 0 <= index < len(segs):
            raise EditRefused(f"no {tier[:-1]} {index + 1} (the {tier} tier has {len(segs)})")
        return segs[index]

    def _selected(self, tier: str | None = None) -> Selection:
        sel = self.selection
        if sel is None or (tier is not None and sel.tier != tier):
            raise EditRefused(f"select a {tier[:-1] if tier else 'segment'} first")
        return sel

    # ------------------------------------------------------------------ times
    def snap(self, t: float) -> float:
        """``t`` on the nearest frame (the model's marker frames), within the recording."""
        t = round(float(t) * self.frame_rate) / self.frame_rate
        return float(min(max(t, 0.0), self.duration))

    def _inside(self, t: float, lo: float, hi: float, what: str) -> float:
        """``t`` snapped to a frame strictly between ``lo`` and ``hi`` (the nearest such frame
        when the snap lands on or beyond them), else :class:`EditRefused`."""
        rate = self.frame_rate
        first = np.floor(lo * rate + 1e-9) + 1          # the first frame after lo
        last = np.ceil(hi * rate - 1e-9) - 1            # the last frame before hi
        if first > last:
            raise EditRefused(f"{what}: no frame between {lo:.3f} and {hi:.3f} s "
                              f"(frames are {1000 / rate:.1f} ms apart)")
        k = min(max(round(float(t) * rate), first), last)
        return float(k / rate)

    # ------------------------------------------------------------------ phone edits
    def check_phone(self, label: str) -> str:
        """``label`` as a phone of the model (normalised: ``M`` → ``m``, ``AH0`` → ``ah``, ``sp``
        → ``sil``), else :class:`EditRefused` saying why."""
        raw = label.strip()
        if not raw:
            raise EditRefused("type a phone (or mark the segment as silence)")
        phone = normalise_label(raw)
        if phone in self.known:
            return phone
        if phone in ARPABET:
            raise EditRefused(f"/{phone}/ is an ARPAbet phone the model was not trained on "
                              f"(its phones: {' '.join(sorted(self.known - {SILENCE}))})")
        raise EditRefused(f"{raw!r} is not a phone of the model (ARPAbet: "
                          f"{' '.join(sorted(self.known - {SILENCE}))}, or sil)")

    def rename(self, label: str, tier: str | None = None) -> Edit:
        """Rename the selected segment: a phone to a phone of the model (:meth:`check_phone`), a
        word to any text."""
        sel = self._selected(tier)
        seg = self._segment(sel.tier, sel.index)
        if sel.tier == PHONES:
            new = self.check_phone(label)
            what = f"rename {shown(seg.label)} → {shown(new)}"
        else:
            new = " ".join(label.split())
            if not new:
                raise EditRefused("a word needs text (delete it to leave a gap)")
            what = f"rename “{seg.label}” → “{new}”"
        if new == seg.label:
            raise EditRefused(f"the {sel.tier[:-1]} is {shown(new) if sel.tier == PHONES else new} already")
        segs = list(self.segments(sel.tier))
        segs[sel.index] = PhoneSegment(seg.start, seg.end, new)
        return self._apply(f"{what} at {seg.start:.3f} s", self._with(sel.tier, segs), sel)

    def mark_silence(self) -> Edit:
        """The selected phone becomes silence."""
        sel = self._selected(PHONES)
        seg = self._segment(PHONES, sel.index)
        if seg.label == SILENCE:
            raise EditRefused("the phone is silence already")
        segs = list(self.phones)
        segs[sel.index] = PhoneSegment(seg.start, seg.end, SILENCE)
        return self._apply(f"mark {shown(seg.label)} at {seg.start:.3f} s as silence",
                           self._with(PHONES, segs), sel)

    def move_boundary(self, index: int, t: float, tier: str = PHONES) -> Edit:
        """Move the boundary at the start of segment ``index`` of ``tier`` to ``t`` (snapped to
        a frame, never onto or past the neighbours' other ends). On the words tier the boundary
        is a word's start (``index``) shared with the word before when they touch; the phone
        boundary on it moves with it."""
        if tier == WORDS:
            return self.move_word_edge(index, "start", t)
        segs = list(self.phones)
        if not 0 < index < len(segs):
            raise EditRefused("the first phone starts at 0 s and the last ends with the recording")
        left, right = segs[index - 1], segs[index]
        new = self._inside(t, left.start, right.end, "the boundary")
        if abs(new - right.start) < SAME_S:
            raise EditRefused(f"the boundary is at {new:.3f} s already")
        segs[index - 1] = PhoneSegment(left.start, new, left.label)
        segs[index] = PhoneSegment(new, right.end, right.label)
        words = self._words_following(right.start, new)
        what = (f"move the boundary {shown(left.label)}|{shown(right.label)} "
                f"{right.start:.3f} → {new:.3f} s")
        return self._apply(what, Tiers(tuple(segs), words), self.selection)

    def split(self, t: float) -> Edit:
        """Split the selected segment at ``t`` (snapped to a frame inside it): two segments with
        its label, the second selected."""
        sel = self._selected()
        seg = self._segment(sel.tier, sel.index)
        name = shown(seg.label) if sel.tier == PHONES else f"“{seg.label}”"
        at = self._inside(t, seg.start, seg.end, f"split {name}")
        segs = list(self.segments(sel.tier))
        segs[sel.index:sel.index + 1] = [PhoneSegment(seg.start, at, seg.label),
                                         PhoneSegment(at, seg.end, seg.label)]
        return self._apply(f"split {name} at {at:.3f} s", self._with(sel.tier, segs),
                           Selection(sel.tier, sel.index + 1))

    def merge_next(self) -> Edit:
        """Merge the selected segment with the next one (its label kept; two words' texts
        joined)."""
        sel = self._selected()
        segs = list(self.segments(sel.tier))
        if sel.index + 1 >= len(segs):
            raise EditRefused(f"the last {sel.tier[:-1]} has no next one to merge with")
        a, b = segs[sel.index], segs[sel.index + 1]
        label = a.label if sel.tier == PHONES else f"{a.label} {b.label}"
        segs[sel.index:sel.index + 2] = [PhoneSegment(a.start, b.end, label)]
        if sel.tier == PHONES:
            what = f"merge {shown(a.label)} with {shown(b.label)} at {a.start:.3f} s"
        else:
            what = f"merge “{a.label}” with “{b.label}”"
        return self._apply(what, self._with(sel.tier, segs), sel)

    def delete(self) -> Edit:
        """Delete the selected segment: a phone's time goes to the phone before it (the first
        phone's to the next); a word leaves a gap (its phones stay)."""
        sel = self._selected()
        segs = list(self.segments(sel.tier))
        seg = segs[sel.index]
        if sel.tier == WORDS:
            del segs[sel.index]
            nxt = min(sel.index, len(segs) - 1)
            return self._apply(f"delete the word “{seg.label}” at {seg.start:.3f} s",
                               self._with(WORDS, segs), Selection(WORDS, nxt) if segs else None)
        if len(segs) == 1:
            raise EditRefused("the only phone cannot be deleted (mark it as silence)")
        if sel.index > 0:
            before = segs[sel.index - 1]
            segs[sel.index - 1] = PhoneSegment(before.start, seg.end, before.label)
            taker, keep = before, sel.index - 1
        else:
            after = segs[1]
            segs[1] = PhoneSegment(seg.start, after.end, after.label)
            taker, keep = after, 0
        del segs[sel.index]
        return self._apply(f"delete {shown(seg.label)} at {seg.start:.3f} s "
                           f"({shown(taker.label)} takes its time)", self._with(PHONES, segs),
                           Selection(PHONES, keep))

    # ------------------------------------------------------------------ word edits
    def move_word_edge(self, index: int, side: str, t: float) -> Edit:
        """Move the ``start`` or ``end`` of word ``index`` to ``t`` (snapped to a frame): not past
        the word's other end or a neighbouring word's far end; a word touching it moves its edge
        too, and the phone boundary lying on the edge moves with it (within its phones)."""
        words = list(self.words)
        w = self._segment(WORDS, index)
        old = w.start if side == "start" else w.end
        eps = 1e-6          # a word may come to touch its neighbour, or reach 0 s or the end
        if side == "start":
            touching = index > 0 and abs(words[index - 1].end - old) < SAME_S
            lo = words[index - 1].start if touching else (
                words[index - 1].end - eps if index else -eps)
            hi = w.end
        elif side == "end":
            touching = index + 1 < len(words) and abs(words[index + 1].start - old) < SAME_S
            lo = w.start
            hi = words[index + 1].end if touching else (
                words[index + 1].start + eps if index + 1 < len(words) else self.duration + eps)
        else:
            raise EditRefused(f"a word has a start and an end, not {side!r}")
        new = self._inside(t, lo, hi, f"the {side} of “{w.label}”")
        if abs(new - old) < SAME_S:
            raise EditRefused(f"the {side} of “{w.label}” is at {new:.3f} s already")
        phones = self._phones_following(old, new)
        if side == "start":
            words[index] = PhoneSegment(new, w.end, w.label)
            if touching:
                p = words[index - 1]
                words[index - 1] = PhoneSegment(p.start, new, p.label)
        else:
            words[index] = PhoneSegment(w.start, new, w.label)
            if touching:
                n = words[index + 1]
                words[index + 1] = PhoneSegment(new, n.end, n.label)
        return self._apply(f"move the {side} of “{w.label}” {old:.3f} → {new:.3f} s",
                           Tiers(phones, tuple(words)), self.selection)

    def _phones_following(self, old: float, new: float) -> tuple[PhoneSegment, ...]:
        """The phones with the boundary at ``old`` (if one is there) moved to ``new``; refused
        when that would cross a phone's other end."""
        phones = list(self.phones)
        k = next((i for i in range(1, len(phones)) if abs(phones[i].start - old) < SAME_S), None)
        if k is None:
            return tuple(phones)
        left, right = phones[k - 1], phones[k]
        if not left.start < new < right.end:
            raise EditRefused(f"the phone boundary at {old:.3f} s cannot follow the word edge to "
                              f"{new:.3f} s: {shown(left.label if new <= left.start else right.label)} "
                              f"would vanish (move the phones first)")
        phones[k - 1] = PhoneSegment(left.start, new, left.label)
        phones[k] = PhoneSegment(new, right.end, right.label)
        return tuple(phones)

    def _words_following(self, old: float, new: float) -> tuple[PhoneSegment, ...]:
        """The words whose edge lies on a phone boundary moved from ``old`` to ``new``, moved with
        it where they stay words (a word is never made empty by a phone boundary)."""
        out = []
        for w in self.words:
            start = new if abs(w.start - old) < SAME_S else w.start
            end = new if abs(w.end - old) < SAME_S else w.end
            out.append(PhoneSegment(start, end, w.label) if end - start > SAME_S else w)
        return tuple(out)

    def add_word(self, start: float, end: float, text: str) -> Edit:
        """A new word over ``[start, end]`` (snapped; in a gap of the words tier), e.g. over the
        phones selected, for labels that have no words (recognized)."""
        text = " ".join(text.split())
        if not text:
            raise EditRefused("a word needs text")
        a, b = self.snap(start), self.snap(end)
        if b - a < SAME_S:
            raise EditRefused("a word needs a length")
        words = list(self.words)
        if any(w.start < b - SAME_S and a < w.end - SAME_S for w in words):
            raise EditRefused(f"{a:.3f}-{b:.3f} s overlaps a word (a new word goes in a gap)")
        words.append(PhoneSegment(a, b, text))
        words.sort(key=lambda w: w.start)
        return self._apply(f"add the word “{text}” at {a:.3f} s", self._with(WORDS, words),
                           Selection(WORDS, words.index(PhoneSegment(a, b, text))))

    def _with(self, tier: str, segs: list[PhoneSegment]) -> Tiers:
        if tier == PHONES:
            return Tiers(tuple(segs), self.tiers.words)
        return Tiers(self.tiers.phones, tuple(segs))


def is_silence(label: str) -> bool:
    """Whether a phone label is silence.

    >>> is_silence("sil"), is_silence("sp"), is_silence("m")
    (True, True, False)
    """
    return label.strip().lower() in SILENCE_LABELS


__all__ = ["PHONES", "WORDS", "Edit", "EditRefused", "LabelDocument", "Selection", "Tiers",
           "is_silence", "shown"]
