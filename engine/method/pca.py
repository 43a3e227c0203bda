"""Principal component analysis of the 3M-dimensional marker vector (paper section 2.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .moments import Moments


@dataclass
class PCA:
    """A fitted PCA: ``x ~ mean + coeffs @ components``.

    Attributes
    ----------
    mean : ``(D,)`` mean vector (the neutral face, flattened ``M x 3``).
    components : ``(K, D)`` orthonormal eigenvectors, largest variance first.
    variances : ``(K,)`` variance of each component's coefficient.
    total_variance : total variance of the data (sum over all D dimensions).
    """

    mean: np.ndarray
    components: np.ndarray
    variances: np.ndarray
    total_variance: float

    @property
    def n_components(self) -> int:
        return int(self.components.shape[0])

    @property
    def explained_ratio(self) -> np.ndarray:
        """Share of the total variance explained by each component."""
        return self.variances / self.total_variance

    def transform(self, x: np.ndarray) -> np.ndarray:
        """Coefficients ``(..., K)`` of vectors ``(..., D)``."""
        return (np.asarray(x) - self.mean) @ self.components.T

    def inverse(self, coeffs: np.ndarray) -> np.ndarray:
        """Vectors ``(..., D)`` from coefficients ``(..., K)`` (the mean added in place: no second
        array of the result's size)."""
        out = np.asarray(coeffs) @ self.components
        out += self.mean
        return out


def fit_pca(x: np.ndarray, n_components: int | None = 20, variance_target: float = 0.99) -> PCA:
    """PCA of the rows of ``x`` (``(T, D)``): :func:`pca_of` their :class:`Moments`.

    Keeps ``n_components``, or when it is ``None`` the smallest count whose cumulative explained
    variance reaches ``variance_target``. With ``n_components = D`` reconstruction is exact.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> x = rng.standard_normal((200, 2)) @ np.array([[3.0, 0.0], [0.0, 0.1]])
    >>> p = fit_pca(x, n_components=None, variance_target=0.99)
    >>> p.n_components, bool(np.allclose(np.abs(p.components[0]), [1, 0], atol=0.01))
    (1, True)
    """
    return pca_of(Moments.of(x), n_components, variance_target)


def pca_of(moments: Moments, n_components: int | None = 20, variance_target: float = 0.99) -> PCA:
    """The PCA of the rows whose count, mean and scatter matrix are ``moments`` (gathered an
    utterance at a time in training): the eigen-decomposition of the ``D x D`` scatter matrix,
    whose eigenvectors are the right singular vectors of the centred rows and whose eigenvalues
    their squared singular values. ``n_components`` and ``variance_target`` as in
    :func:`fit_pca`."""
    ev, vec = np.linalg.eigh(moments.scatter)
    ev, vec = np.clip(ev[::-1], 0.0, None), vec[:, ::-1]
    vt = vec.T
    var = ev / max(moments.n - 1, 1)
    total = float(var.sum())
    if n_components is None:
        cum = np.cumsum(var) / total
        k = int(np.searchsorted(cum, variance_target - 1e-12) + 1)
    else:
        k = int(n_components)
    k = max(1, min(k, vt.shape[0]))
    comps = vt[:k].copy()
    # a sign convention so that a component's largest loading is positive (stable across runs)
    signs = np.sign(comps[np.arange(k), np.abs(comps).argmax(axis=1)])
    comps *= signs[:, None]
    return PCA(mean=moments.mean, components=comps, variances=var[:k], total_variance=total)
