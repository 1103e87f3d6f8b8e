"""ExperimentalData: the measured vector y_exp, its control values and covariance C_exp, in named blocks.

A dataset is one or more blocks (specimens, local data such as FPZ width [mm]), each a contiguous slice of
``y``; :func:`stack` joins datasets with a block-diagonal covariance, and
:meth:`ExperimentalData.weighted` weights the blocks (docs/theory.md, section 3.3). The builders of a
block from measured curves are in :mod:`fracid.data.experimental`.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, replace

import numpy as np

from fracid.data.covariance_matrix import Covariance, as_covariance, block_diagonal
from fracid.data.errors import DataError


@dataclass(frozen=True, eq=False)
class ExperimentalData:
    """Measured vector y_exp, its sampling points and covariance C_exp.

    Parameters
    ----------
    control : array_like, shape (n_y,)
        Control value [mm] at which each entry of ``y`` is taken.
    y : array_like, shape (n_y,)
        Measured values: forces [N] (global blocks) or local quantities (e.g. width [mm]).
    covariance : array_like, shape (n_y, n_y), or Covariance
        Covariance C_exp [N^2, or the local unit squared], symmetric positive definite; kept as a
        :class:`~fracid.data.covariance_matrix.Covariance` (a :class:`~fracid.data.covariance_matrix.Diagonal`
        when diagonal, so that n_y may be large). It reads as an (n_y, n_y) array while n_y is small
        (``np.asarray(data.covariance)``, ``data.covariance.shape``, ``data.covariance[s, s]``).
    blocks : tuple of (str, int, int)
        (name, start, stop) of each stacked block: ``y[start:stop]``; contiguous, covering all of
        ``y``, names unique.
    notes : tuple of str
        Every rule applied to build the data.

    Raises
    ------
    DataError
        If shapes disagree, values are not finite, the covariance is not symmetric positive definite
        or the blocks do not tile ``y``.
    """

    control: np.ndarray
    y: np.ndarray
    covariance: Covariance
    blocks: tuple[tuple[str, int, int], ...]
    notes: tuple[str, ...] = ()

    def __post_init__(self):
        control = np.array(self.control, dtype=float)
        y = np.array(self.y, dtype=float)
        if y.ndim != 1 or y.size == 0:
            raise DataError(f"y must be a non-empty one-dimensional array, got shape {y.shape}")
        n = y.size
        if control.shape != (n,):
            raise DataError(f"control must have shape ({n},) like y, got {control.shape}")
        for what, array in (("control", control), ("y", y)):
            if not np.all(np.isfinite(array)):
                raise DataError(f"{what} holds non-finite values")
        cov = _check_covariance(self.covariance, n)
        blocks = _check_blocks(self.blocks, n)
        for array in (control, y):
            array.setflags(write=False)
        object.__setattr__(self, "control", control)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "covariance", cov)
        object.__setattr__(self, "blocks", blocks)
        object.__setattr__(self, "notes", tuple(str(note) for note in self.notes))

    @property
    def n_y(self) -> int:
        """Number of entries of y."""
        return int(self.y.size)

    @property
    def std(self) -> np.ndarray:
        """Standard deviation of each entry, sqrt(diag(covariance)) [N or the local unit]."""
        return self.covariance.std()

    def weighted(self, weights: dict) -> "ExperimentalData":
        """The data with block weights p_b: f = sum_b p_b f_b (docs/theory.md, section 3.3, e.g. p1 global, p2 local).

        The objective f = r^T C^-1 r of a block times p_b is the objective with its covariance
        divided by p_b, so the Kalman filter and KNN see the same weighting.

        Parameters
        ----------
        weights : dict of str -> float
            Block name -> p_b > 0; blocks not named keep p = 1.
        """
        scale = np.ones(self.n_y)
        names = [b[0] for b in self.blocks]
        for name, p in weights.items():
            if name not in names:
                raise DataError(f"weight for block {name!r}: no such block; blocks: {', '.join(names)}")
            if not (np.isfinite(p) and p > 0):
                raise DataError(f"weight of block {name!r} = {p!r}: it must be a number > 0")
            scale[self.block(name)] = 1.0 / np.sqrt(p)
        notes = [f"block {name!r} weighted p = {p:g} (covariance divided by p)" for name, p in weights.items() if p != 1]
        return replace(self, covariance=self.covariance.scaled(scale), notes=self.notes + tuple(notes))

    def block(self, name: str) -> slice:
        """Slice of ``y`` holding the block ``name``."""
        for block_name, start, stop in self.blocks:
            if block_name == name:
                return slice(start, stop)
        raise KeyError(f"no block {name!r}; blocks: {', '.join(b[0] for b in self.blocks)}")


def _check_covariance(covariance, n: int) -> Covariance:
    """``covariance`` as a :class:`~fracid.data.covariance_matrix.Covariance` of n values (Diagonal when it is
    diagonal); DataError if it is not an (n, n) array or a covariance of n values, not finite, not symmetric
    or not positive definite."""
    if not isinstance(covariance, Covariance):
        try:
            covariance = np.asarray(covariance, dtype=float)
        except (TypeError, ValueError):
            raise DataError(f"covariance is a {type(covariance).__name__}, not an array of numbers") from None
        if covariance.shape != (n, n):
            raise DataError(f"covariance must have shape ({n}, {n}), got {covariance.shape}")
    try:
        return as_covariance(covariance, n, name="covariance")
    except ValueError as err:
        raise DataError(str(err)) from None


def _check_blocks(blocks, n: int) -> tuple[tuple[str, int, int], ...]:
    """``blocks`` as (name, start, stop) triples, checked to tile range(n) contiguously with unique names."""
    try:
        checked = tuple((str(name), operator.index(start), operator.index(stop)) for name, start, stop in blocks)
    except (TypeError, ValueError):
        raise DataError(f"blocks must be (name, start, stop) triples with integer bounds, got {blocks!r}") from None
    if not checked:
        raise DataError("blocks is empty: give at least one (name, start, stop)")
    expected = 0
    for name, start, stop in checked:
        if start != expected or stop <= start:
            raise DataError(f"blocks must tile y contiguously from 0 to {n}; block {name!r} is [{start}, {stop})")
        expected = stop
    if expected != n:
        raise DataError(f"blocks must tile y contiguously from 0 to {n}; they end at {expected}")
    names = [b[0] for b in checked]
    if len(set(names)) != len(names):
        raise DataError(f"block names must be unique, got {names}")
    return checked


def _unique_name(name: str, used: set[str]) -> str:
    """``name``, or ``name_2``, ``name_3``, ... : the first not in ``used``."""
    if name not in used:
        return name
    k = 2
    while f"{name}_{k}" in used:
        k += 1
    return f"{name}_{k}"


def stack(*datasets: ExperimentalData) -> ExperimentalData:
    """Stack datasets into one y_exp with a block-diagonal covariance.

    Block names are made unique by appending ``_2``, ``_3``, ... to repeated names (noted); each
    dataset's notes are kept, prefixed by its (final) block names.

    Raises
    ------
    DataError
        If no dataset is given or an argument is not ExperimentalData.
    """
    if not datasets:
        raise DataError("stack needs at least one ExperimentalData")
    for k, data in enumerate(datasets):
        if not isinstance(data, ExperimentalData):
            raise DataError(f"stack argument {k + 1} is {type(data).__name__}, not ExperimentalData")
    used: set[str] = set()
    blocks, renames, notes_per_data = [], [], []
    offset = 0
    for k, data in enumerate(datasets):
        final = []
        for name, start, stop in data.blocks:
            new = _unique_name(name, used)
            used.add(new)
            if new != name:
                renames.append(f"block {name!r} of dataset {k + 1} renamed {new!r} (block names must be unique)")
            blocks.append((new, start + offset, stop + offset))
            final.append(new)
        notes_per_data.append([f"[{'+'.join(final)}] {note}" for note in data.notes])
        offset += data.n_y
    layout = ", ".join(f"{name} [{start}:{stop})" for name, start, stop in blocks)
    notes = [f"stacked {len(datasets)} datasets, block-diagonal covariance: {layout}", *renames]
    for data_notes in notes_per_data:
        notes += data_notes
    return ExperimentalData(
        control=np.concatenate([d.control for d in datasets]),
        y=np.concatenate([d.y for d in datasets]),
        covariance=block_diagonal([d.covariance for d in datasets]),
        blocks=tuple(blocks),
        notes=tuple(notes),
    )
