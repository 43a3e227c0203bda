"""The training utterances as training reads them: one at a time, by index, from a corpus folder
or from utterances in memory, never all at once.

Training (:mod:`facetraj_engine.method.training`) passes over them three times, as the paper's steps
need the results of the steps before over the whole set (section 2.1: the neutral head pose
before head-motion removal, the PCA of every head-normalised frame before the codewords' PC
vectors). The first pass loads every utterance whole; the later ones read its markers alone
(:meth:`TrainingSet.markers`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..data import Utterance
from ..io.corpus import Corpus


@dataclass
class MarkerSetup:
    """Which markers are which, for training on utterances outside a corpus folder."""

    fixed: list[str]
    upper_lip: str
    lower_lip: str
    lip_corners: list[str] = field(default_factory=list)
    #: articulograph sensors' roles where their names do not say them (``corpus.json``)
    sensor_roles: dict[str, list[str]] = field(default_factory=dict)


@dataclass
class TrainingSet:
    """The training utterances (``names``, in order), their marker roles (``setup``), the marker
    set and rate every one must have, and the corpus fingerprint (``""`` outside a corpus).

    Build it with :meth:`of`; :meth:`utterance` loads one whole, :meth:`markers` reads one's
    markers alone."""

    names: list[str]
    setup: MarkerSetup
    marker_names: list[str]
    marker_rate: float
    fingerprint: str = ""
    corpus: Corpus | None = None
    loaded: Sequence[Utterance] = ()

    @classmethod
    def of(cls, utterances: Iterable[Utterance] | Corpus, setup: MarkerSetup | None
           ) -> TrainingSet:
        """A :class:`~facetraj_engine.io.corpus.Corpus`'s ``train`` split, with its ``corpus.json`` roles
        unless ``setup`` is given; or utterances in memory, with ``setup`` (required), the marker
        set of the first one that has markers."""
        if isinstance(utterances, Corpus):
            info = utterances.info
            setup = setup or MarkerSetup(info.fixed_markers, info.upper_lip, info.lower_lip,
                                         info.lip_corners, dict(info.sensor_roles))
            return cls(list(info.train), setup, list(info.marker_names), float(info.marker_rate),
                       utterances.fingerprint(), corpus=utterances)
        if setup is None:
            raise ValueError("pass a MarkerSetup (fixed markers and lips) when not training on a "
                             "Corpus")
        loaded = list(utterances)
        first = next((u for u in loaded if u.markers is not None), loaded[0] if loaded else None)
        return cls([u.name for u in loaded], setup,
                   list(first.marker_names) if first else [],
                   float(first.marker_rate) if first else 60.0, loaded=loaded)

    def __len__(self) -> int:
        return len(self.names)

    def utterance(self, k: int) -> Utterance:
        """Utterance ``k``, whole (audio, labels, markers)."""
        return self.corpus.utterance(self.names[k]) if self.corpus is not None else self.loaded[k]

    def markers(self, k: int, n_frames: int) -> np.ndarray:
        """Utterance ``k``'s markers ``(n_frames, M, 3)`` alone, as :meth:`utterance` gives
        them (its audio's ``n_frames`` frames)."""
        if self.corpus is not None:
            return self.corpus.markers(self.names[k], n_frames)
        return self.loaded[k].markers
