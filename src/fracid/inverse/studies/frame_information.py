"""Which frames of a full-field block carry the information: the Fisher information of each frame, ranked.

A DIC camera records many frames; each costs nothing to keep but adds values to every identification, and
they are far from equally informative (docs/dic/design.md: the softening frames carry most of what the curve
lacks). At given parameters (the configuration's, before anything is identified) :func:`frame_information`
gives each frame's Fisher information F_k = S_k^T C_k^-1 S_k (S_k the sensitivities of the frame's values,
C_k their covariance: frames are independent blocks of the data covariance), and :func:`rank_frames` orders
the frames greedily, each time the one that shrinks the posterior's volume most (log det of
(P + sum F)^-1, P the prior's information), and follows the stds and the largest correlation along that
order. The frames advised are the shortest prefix whose largest ``|r|`` is at most ``target`` (0.8: no longer
"strongly correlated") or, when no set reaches it, within ``within`` of what all frames give.

Trust: a linearisation at the parameters given; where they are far from the truth the ranking can change
(the check says at which parameters it is computed). Units: each parameter's own (S per unit parameter).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FrameRanking", "frame_information", "rank_frames"]


def frame_information(S, C_exp, slices) -> list:
    """The Fisher information S_k^T C_k^-1 S_k (p x p) of every frame's entries.

    Parameters
    ----------
    S : ndarray (n, p)
        Sensitivities of all values [units of y per unit of each parameter].
    C_exp : Covariance
        Their covariance (:class:`~fracid.data.covariance_matrix.Covariance`); the frames' entries independent
        of each other's.
    slices : sequence of slice or index arrays
        Each frame's entries.
    """
    S = np.asarray(S, float)
    return [S[rows].T @ C_exp.take(rows).solve(S[rows]) for rows in slices]


@dataclass(frozen=True)
class FrameRanking:
    """The frames in the order of :func:`rank_frames`, and what each prefix of that order gives.

    Attributes
    ----------
    names : tuple of str
        Parameters.
    labels : tuple of str
        Each frame's label (in the frames' own order).
    order : tuple of int
        Frame positions, the most informative first.
    std : ndarray (n_frames, p)
        Posterior std of each parameter with the first k + 1 frames of ``order`` [its unit].
    largest_r : ndarray (n_frames,)
        The largest ``|r|`` between two parameters with those frames.
    pairs : tuple of (str, str)
        The pair with that ``|r|``.
    advised : tuple of int
        The frames advised (positions, in ``order``'s order).
    target : float
        The ``|r|`` the advice aims at.
    """

    names: tuple
    labels: tuple
    order: tuple
    std: np.ndarray
    largest_r: np.ndarray
    pairs: tuple
    advised: tuple
    target: float

    def lines(self, shown: int = 8) -> list:
        """Text lines: the first ``shown`` frames of the order with the stds and ``|r|`` they give, the advice."""
        lines = []
        for k, frame in enumerate(self.order[:shown]):
            stds = ", ".join(f"{name} {s:.3g}" for name, s in zip(self.names, self.std[k]))
            a, b = self.pairs[k]
            lines.append(f"  {k + 1}. {self.labels[frame]}: std {stds}; largest |r| {self.largest_r[k]:.3f} "
                         f"({a}, {b})")
        if len(self.order) > shown:
            lines.append(f"  ... all {len(self.order)} frames: largest |r| {self.largest_r[-1]:.3f}")
        n = len(self.advised)
        reached = self.largest_r[n - 1] <= self.target
        lines.append(f"frames advised: {', '.join(self.labels[f] for f in self.advised)} ({n} of {len(self.order)}: "
                     + (f"largest |r| {self.largest_r[n - 1]:.3f} <= {self.target:g}" if reached else
                        f"no set brings |r| to {self.target:g}; these give {self.largest_r[n - 1]:.3f}, all frames "
                        f"{self.largest_r[-1]:.3f}") + ")")
        return lines


def _posterior(information: np.ndarray) -> tuple:
    """(std, largest ``|r|``, its pair of indices, log det of the covariance) of the information matrix. Inverted in
    the scale of its own diagonal: the parameters' units differ by many orders (1e13 for kappa_i against 1e-3
    for beta), which an unscaled inverse or pseudo-inverse cuts at its relative tolerance."""
    d = np.sqrt(np.clip(np.diag(information), 0.0, None))
    seen = d > 0
    scale = np.where(seen, d, 1.0)
    scaled = information / np.outer(scale, scale)
    sign, logdet = np.linalg.slogdet(scaled)
    if sign <= 0 or not np.all(seen):  # a parameter or a combination unseen: infinite volume
        C, volume = np.linalg.pinv(scaled, hermitian=True), np.inf
    else:
        C, volume = np.linalg.inv(scaled), -(logdet + 2.0 * np.sum(np.log(d)))
    std = np.sqrt(np.clip(np.diag(C), 0.0, None)) / scale
    unit = np.sqrt(np.clip(np.diag(C), 1e-300, None))
    r = np.abs(C / np.outer(unit, unit))
    np.fill_diagonal(r, 0.0)
    i, j = np.unravel_index(int(np.argmax(r)), r.shape)
    return std, float(r[i, j]), (min(i, j), max(i, j)), volume


def rank_frames(information, names, prior=None, *, labels=None, target: float = 0.8,
                within: float = 0.05) -> FrameRanking:
    """Frames ordered greedily by the posterior volume they leave, and the frames advised.

    Parameters
    ----------
    information : sequence of ndarray (p, p)
        Each frame's Fisher information (:func:`frame_information`).
    names : sequence of str
        The parameters.
    prior : ndarray (p, p), optional
        The prior's information (e.g. the inverse of the covariance the bounds give); default none (a frame
        that leaves a parameter unseen then has an infinite volume and comes later).
    labels : sequence of str, optional
        Each frame's label (default "frame k", k from 1).
    target : float
        The largest ``|r|`` the advised frames should reach.
    within : float
        Without a set reaching ``target``: the advised frames' largest ``|r|`` is within this of all frames'.

    Returns
    -------
    FrameRanking
    """
    blocks = [np.asarray(F, float) for F in information]
    if not blocks:
        raise ValueError("rank_frames needs at least one frame's information")
    p = len(names)
    base = np.zeros((p, p)) if prior is None else np.asarray(prior, float)
    labels = tuple(labels) if labels is not None else tuple(f"frame {k + 1}" for k in range(len(blocks)))
    order, stds, largest, pairs, total = [], [], [], [], base.copy()
    remaining = list(range(len(blocks)))
    while remaining:
        volumes = [_posterior(total + blocks[k])[3] for k in remaining]
        best = remaining.pop(int(np.argmin(volumes)))
        total = total + blocks[best]
        std, r, (i, j), _ = _posterior(total)
        order.append(best)
        stds.append(std)
        largest.append(r)
        pairs.append((names[i], names[j]))
    largest = np.array(largest)
    goal = target if np.any(largest <= target) else largest[-1] + within
    n = int(np.argmax(largest <= goal + 1e-12)) + 1
    return FrameRanking(tuple(names), labels, tuple(order), np.array(stds), largest, tuple(pairs),
                        tuple(order[:n]), float(target))
