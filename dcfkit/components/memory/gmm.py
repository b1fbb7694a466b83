"""ECO's generative sample space model (Danelljan et al., CVPR 2017, Sec. 3.2): a Gaussian
mixture of at most L components, each a stored sample with a prior weight, updated by one
new component per frame (ECO's update_sample_space_model, merge_samples,
update_distance_matrix).

A new sample gets weight η and the others are scaled by 1 - η. When all L slots are used, a
component whose weight fell below η(1 - η)^{2L} is replaced; otherwise the two closest
components merge (weights added, samples averaged by weight), the new sample and its closest
component if they are closer than any pair of kept ones. Distances are Euclidean over the
half spectra as ECO counts them (2 Re <a, b>, every column twice), kept in a Gram matrix
updated by rank-one steps rather than recomputed (float32, as the authors' single arrays).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.memory.base import Memory
from dcfkit.params import param

F32 = np.float32


def inner_products(stored: list[np.ndarray], sample) -> np.ndarray:
    """(N,) float32: 2 Re <slot n, sample> summed over blocks (numpy's own sums, not a BLAS
    product, whose order depends on the processor and the number of threads)."""
    total = np.zeros(stored[0].shape[0], F32)
    for store, block in zip(stored, sample):
        flat, b = store.reshape(store.shape[0], -1), np.ravel(block)
        total += F32(2) * (flat.real * b.real + flat.imag * b.imag).sum(axis=1, dtype=F32)  # Re(x conj(b))
    return total


class GaussianMixture(Memory):
    """ECO's sample space model: at most ``capacity`` weighted components (L of Eq. 8)."""

    name = "gmm"

    @dataclasses.dataclass(frozen=True)
    class Params:
        capacity: int = param(30, "L: the most components (samples) kept", ge=1, le=1000)
        learning_rate: float = param(0.009, "γ: prior weight of each new sample", gt=0, lt=1)
        merge: str = param("merge", "how two components become one: 'merge' their weighted average, 'replace' "
                           "the heavier kept as it is", choices=("merge", "replace"))

    def reset(self) -> None:
        n = self.params.capacity
        self.samples, self.count = [], 0
        self.weights = np.zeros(n, F32)
        self.gram = np.full((n, n), np.inf, F32)
        self.distance = np.full((n, n), np.inf, F32)

    def _gram_vector(self, sample) -> np.ndarray:
        gv = inner_products(self.samples, sample)
        gv[self.count:] = np.inf
        return gv

    def _distances_of(self, i: int) -> None:
        with np.errstate(invalid="ignore"):  # inf - inf of unused slots: 0, as MATLAB's max ignores NaN
            col = np.fmax(self.gram[i, i] + np.diag(self.gram) - F32(2) * self.gram[:, i], F32(0))
        self.distance[:, i] = col
        self.distance[i, :] = col
        self.distance[i, i] = np.inf

    def _update(self, gv: np.ndarray, norm, i: int, j: int, w1, w2) -> None:
        """The Gram and distance matrices after a merge (ECO's update_distance_matrix): j < 0
        merges the new sample into slot i with weights (w1, w2) (w1 = 0: it replaces slot i);
        j >= 0 merges slot j into slot i and puts the new sample in slot j. Not split: the two
        cases share their arithmetic."""
        a1 = F32(w1) / (F32(w1) + F32(w2))
        a2 = F32(1) - a1
        g = self.gram
        with np.errstate(invalid="ignore", over="ignore"):
            if j < 0:
                old = g[i, i]
                if a1 == 0:
                    g[:, i] = gv
                    g[i, :] = g[:, i]
                    g[i, i] = norm
                elif a2 != 0:
                    g[:, i] = a1 * g[:, i] + a2 * gv
                    g[i, :] = g[:, i]
                    g[i, i] = a1 * a1 * old + a2 * a2 * norm + F32(2) * a1 * a2 * gv[i]
                self._distances_of(i)
                return
            ni, nj, nij = g[i, i], g[j, j], g[i, j]
            g[:, i] = a1 * g[:, i] + a2 * g[:, j]
            g[i, :] = g[:, i]
            g[i, i] = a1 * a1 * ni + a2 * a2 * nj + F32(2) * a1 * a2 * nij
            gv = gv.copy()
            gv[i] = a1 * gv[i] + a2 * gv[j]
            g[:, j] = gv
            g[j, :] = g[:, j]
            g[j, j] = norm
        self._distances_of(i)
        self._distances_of(j)

    def _merged(self, a, b, wa, wb):
        if self.params.merge == "replace":
            return [np.array(x) for x in a]
        a1 = F32(wa) / (F32(wa) + F32(wb))
        return [a1 * x + (F32(1) - a1) * y for x, y in zip(a, b)]

    def _store(self, i: int, sample) -> None:
        for store, block in zip(self.samples, sample):
            store[i] = block

    def insert(self, sample) -> None:
        """Not split: ECO's one decision between four updates."""
        if not self.samples:
            self._allocate(sample, self.params.capacity)
        n, lr, w = self.params.capacity, F32(self.params.learning_rate), self.weights
        gv = self._gram_vector(sample)
        norm = inner_products([np.asarray(b)[None] for b in sample], sample)[0]
        if self.count < n:
            i = self.count
            self._update(gv, norm, i, -1, 0, 1)
            if i == 0:
                w[0] = 1
            else:
                w *= F32(1) - lr
                w[i] = lr
            self._store(i, sample)
            self.count += 1
            return
        low = int(np.argmin(w))
        if w[low] < lr * (F32(1) - lr) ** (2 * n):  # too light to keep: replaced
            self._update(gv, norm, low, -1, 0, 1)
            w[low] = 0
            w *= (F32(1) - lr) / np.sum(w)
            w[low] = lr
            self._store(low, sample)
            return
        with np.errstate(invalid="ignore"):
            to_new = np.fmax(norm + np.diag(self.gram) - F32(2) * gv, F32(0))
        nearest = int(np.argmin(to_new))
        s1, s2 = np.unravel_index(int(np.argmin(self.distance.ravel(order="F"))), self.distance.shape, order="F")
        w *= F32(1) - lr
        if to_new[nearest] < self.distance[s1, s2]:  # the new sample joins its nearest component
            merged = self._merged([s[nearest] for s in self.samples], sample, w[nearest], lr)
            self._update(gv, norm, nearest, -1, w[nearest], lr)
            w[nearest] += lr
            self._store(nearest, merged)
            return
        if w[s2] > w[s1]:  # the heavier of the closest pair keeps the merged component
            s1, s2 = s2, s1
        merged = self._merged([s[s1] for s in self.samples], [s[s2] for s in self.samples], w[s1], w[s2])
        self._update(gv, norm, int(s1), int(s2), w[s1], w[s2])
        w[s1] += w[s2]
        w[s2] = lr
        self._store(s1, merged)
        self._store(s2, sample)

    def replace(self, index: int, sample) -> None:
        """The slot's sample changed (its weight kept): its Gram row and distances recomputed."""
        gv = self._gram_vector(sample)
        norm = inner_products([np.asarray(b)[None] for b in sample], sample)[0]
        self._update(gv, norm, index, -1, 0, 1)
        self._store(index, sample)
