"""The similarity view's numbers (paper eqs 1-3, Table 1): the phones ordered by hierarchical
clustering of the eq 2 distances (visemes group), the dendrogram, and the eq 3 matrix as CSV."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.cluster import hierarchy
from scipy.spatial.distance import squareform

from ..method.model import Model
from .common import write_csv


@dataclass
class PhoneClustering:
    """Hierarchical clustering of the phones on the eq 2 distances.

    ``order`` indexes ``model.phones`` in dendrogram leaf order (phones without tokens, whose
    distances are NaN, come last); ``linkage`` is scipy's linkage matrix over ``clustered``
    (the indices that took part), ``labels`` the phone labels in ``order``.
    """

    order: list[int]
    labels: list[str]
    linkage: np.ndarray
    clustered: list[int]


def cluster_phones(model: Model, method: str = "average") -> PhoneClustering:
    """Order the phones by hierarchical clustering (``scipy.cluster.hierarchy``, optimal leaf
    ordering) of the model's eq 2 distance matrix, so that visually similar phones sit together.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> d = np.array([[0, 9, 1, 9], [9, 0, 9, 2], [1, 9, 0, 9], [9, 2, 9, 0]], dtype=float)
    >>> c = cluster_phones(SimpleNamespace(distances=d, phones=["a", "b", "c", "e"]))
    >>> sorted([sorted(c.labels[:2]), sorted(c.labels[2:])])
    [['a', 'c'], ['b', 'e']]
    """
    d = np.asarray(model.distances, dtype=np.float64)
    ok = [i for i in range(len(d)) if np.isfinite(d[i]).sum() > 1 or len(d) == 1]
    ok = [i for i in ok if np.isfinite(d[i, ok]).all()]
    rest = [i for i in range(len(d)) if i not in ok]
    if len(ok) >= 3:
        sub = d[np.ix_(ok, ok)]
        sub = 0.5 * (sub + sub.T)
        np.fill_diagonal(sub, 0.0)
        z = hierarchy.linkage(squareform(sub, checks=False), method=method)
        z = hierarchy.optimal_leaf_ordering(z, squareform(sub, checks=False))
        leaves = hierarchy.leaves_list(z)
        order = [ok[i] for i in leaves] + rest
    else:
        z = np.zeros((0, 4))
        order = ok + rest
    return PhoneClustering(order, [model.phones[i] for i in order], z, ok)


@dataclass
class Dendrogram:
    """Line segments of a dendrogram (scipy's ``icoord``/``dcoord``): leaf ``k`` of the order sits
    at x = 10 k + 5, heights are eq 2 distances."""

    icoord: list[list[float]]
    dcoord: list[list[float]]
    labels: list[str]


def dendrogram(clustering: PhoneClustering) -> Dendrogram:
    """The dendrogram's segments, leaves in ``clustering.order``."""
    if len(clustering.linkage) == 0:
        return Dendrogram([], [], clustering.labels)
    r = hierarchy.dendrogram(clustering.linkage, no_plot=True, count_sort=False,
                             distance_sort=False)
    return Dendrogram(r["icoord"], r["dcoord"], clustering.labels)


def similarity_in_order(model: Model, nu: float | None, order: Sequence[int]) -> np.ndarray:
    """The eq 3 matrix for ``nu`` with rows and columns in ``order``."""
    s = model.similarity(nu)
    idx = np.asarray(order)
    return s[np.ix_(idx, idx)]


def write_similarity_csv(path: str | os.PathLike[str], model: Model, nu: float | None = None,
                         order: Sequence[int] | None = None, overwrite: bool = True) -> Path:
    """Write the K x K similarity matrix (eq 3, ``nu`` default the model's) as CSV: a header row of
    phones, then one row per phone starting with its label."""
    order = list(range(len(model.phones))) if order is None else list(order)
    s = similarity_in_order(model, nu, order)
    labels = [model.phones[i] for i in order]
    return write_csv(path, ["phone", *labels],
                     ([lab, *map(float, row)] for lab, row in zip(labels, s, strict=True)), overwrite)


__all__ = ["Dendrogram", "PhoneClustering", "cluster_phones", "dendrogram", "similarity_in_order",
           "write_similarity_csv"]
