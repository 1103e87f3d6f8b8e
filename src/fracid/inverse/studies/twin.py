"""Twin experiments: synthetic data from known parameters, to be identified back.

The data are computed by the same forward operator that identifies them, plus Gaussian noise of a
stated standard deviation per block, so the identification's error and its reported uncertainty
can be compared with the truth.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fracid.data import Diagonal, ExperimentalData


def synthetic_data(operator, x_true, std, *, seed: int | None = 0) -> ExperimentalData:
    """Data computed at ``x_true`` with noise, one block per observation of the operator.

    Parameters
    ----------
    operator : ForwardOperator
    x_true : array_like
        The known parameters.
    std : dict of str -> float, or float
        Per block name: the noise standard deviation. A value in (0, 1) with the key suffixed
        ``":relative"`` (e.g. ``{"global:relative": 0.02}``) is relative to the block's largest ``|y|``;
        a plain float applies to every block as relative.
    seed : int or None
        Seed of the noise; None gives noise-free data (with the stated covariance).

    Raises
    ------
    RuntimeError
        If the forward run at ``x_true`` fails.
    """
    record = operator(np.asarray(x_true, float))
    if not record.ok:
        raise RuntimeError(f"the twin's forward run at {list(x_true)} failed: {record.error}")
    y = record.y
    s = np.empty_like(y)
    blocks, notes = [], []
    for obs, part in zip(operator.observations, operator.slices()):
        block_std = _block_std(std, obs.name, y[part])
        s[part] = block_std
        blocks.append((obs.name, part.start, part.stop))
        notes.append(f"twin experiment: block {obs.name!r} computed at {dict(zip(operator.names, np.ravel(x_true)))}, "
                     f"noise std {block_std:.4g}" + ("" if seed is not None else " (not added)"))
    noisy = y if seed is None else y + np.random.default_rng(seed).standard_normal(y.size) * s
    control = np.concatenate([obs.controls for obs in operator.observations])
    return ExperimentalData(control, noisy, Diagonal(s**2), tuple(blocks), tuple(notes))


def _block_std(std, name, values) -> float:
    if isinstance(std, (int, float)):
        return float(std) * float(np.max(np.abs(values)))
    if f"{name}:relative" in std:
        return float(std[f"{name}:relative"]) * float(np.max(np.abs(values)))
    if name in std:
        return float(std[name])
    raise KeyError(f"no noise level for block {name!r}: give std[{name!r}] (absolute) or "
                   f"std['{name}:relative'] (fraction of its largest value)")


@dataclass
class TwinOutcome:
    """Identification of one twin experiment.

    Attributes
    ----------
    name : str
    study : StudyResult
    truth : ndarray
    data : ExperimentalData
    """

    name: str
    study: object
    truth: np.ndarray
    data: ExperimentalData

    @property
    def estimate(self) -> np.ndarray:
        return self.study.identification.x

    @property
    def relative_error(self) -> np.ndarray:
        """(estimate - truth) / truth per parameter."""
        return (self.estimate - self.truth) / np.abs(self.truth)

    @property
    def relative_std(self) -> np.ndarray:
        """Posterior standard deviation / ``|estimate|``: the expected estimation error."""
        ident = self.study.identification
        return ident.std / np.abs(ident.x)

    @property
    def correlation(self) -> np.ndarray:
        return self.study.identification.correlation

    def row(self) -> dict:
        names = self.study.names
        out = {"case": self.name, "n_y": int(self.data.n_y)}
        for j, n in enumerate(names):
            out[f"{n}_estimate"] = float(self.estimate[j])
            out[f"{n}_error"] = float(self.relative_error[j])
            out[f"{n}_rel_std"] = float(self.relative_std[j])
            out[f"{n}_verdict"] = self.study.verdict[n].status
        for a in range(len(names)):
            for b in range(a + 1, len(names)):
                out[f"corr_{names[a]}_{names[b]}"] = float(self.correlation[a, b])
        return out


def twin_matrix(cases: dict, x_true, std, space, settings=None, *, seed: int | None = 1, log=None, executor=None,
                store=None, progress=None, retry_failed=False, **changes) -> dict:
    """Twin experiments over several data sets: synthetic data per case, then the study.

    Parameters
    ----------
    cases : dict of str -> ForwardOperator
        The data set of each case (e.g. one size; three sizes; global plus local).
    x_true : array_like
        Known parameters.
    std : dict or float
        Noise per block, see :func:`synthetic_data`.
    space : ParameterSpace
    settings : StudySettings, optional
        Settings of every study (:class:`~fracid.inverse.studies.study.StudySettings`; its defaults if None).
    seed : int or None
        Noise seed, the same for every case.
    executor, store, progress, retry_failed
        Execution of the studies, as in :func:`~fracid.inverse.studies.study.run_study`.
    changes
        Changes to ``settings`` by name (:meth:`StudySettings.replace`, e.g. ``n=16, starts=0``).

    Returns
    -------
    dict of str -> TwinOutcome
    """
    from fracid.inverse.studies.study import StudySettings, run_study

    settings = (StudySettings() if settings is None else settings).replace(**changes)
    x_true = np.asarray(x_true, float)
    outcomes = {}
    for name, operator in cases.items():
        if log is not None:
            log(f"twin case {name!r}")
        data = synthetic_data(operator, x_true, std, seed=seed)
        study = run_study(operator, data, space, settings, executor=executor, store=store, progress=progress,
                          retry_failed=retry_failed)
        outcomes[name] = TwinOutcome(name, study, x_true, data)
    return outcomes


def dogbone_cases(params, names=("c", "beta"), *, sizes=(50.0, 100.0, 200.0), reference=100.0, h_fine=2.5,
                  n_points=15, damage_threshold=0.5, model=None) -> dict:
    """The four data sets of the thesis's identifiability study on dog-bones (van Vliet & van Mier; docs/theory.md, section 4.9).

    ``one size``: the force-elongation curve of the ``reference`` size; ``three sizes``: the curves
    of all ``sizes``; ``local only``: the FPZ width (damage above ``damage_threshold``) of the
    reference size; ``one size + local``: the reference curve and its FPZ width; ``all``: every
    curve and the reference FPZ width.

    Each curve is sampled at ``n_points`` elongations from 1/n_points of the range to where the
    force at ``params`` has fallen to 20 % of its peak (or the specimen's default target).

    ``model`` is the forward model (:mod:`fracid.models`) of the curves and of every case's operator;
    ``DamageModel("gradient")`` when None.
    """
    from fracid.inverse.core.forward_operator import ForwardOperator, Observation
    from fracid.models import DamageModel
    from fracid.specimens.dogbone import DogBone

    model = DamageModel("gradient") if model is None else model

    if reference not in sizes:
        raise ValueError(f"the reference size {reference} must be one of the sizes {sizes}")
    curves, local = {}, {}
    for D in sizes:
        specimen = DogBone(size=float(D), h_fine=h_fine)
        run = model.simulate(specimen, params, stop_force_fraction=0.2)
        points = np.linspace(run.control[-1] / n_points, run.control[-1], n_points)
        curves[D] = Observation(specimen, points, name=f"force D{D:g}")
        local[D] = Observation(specimen, points, quantity="fpz_width", name=f"fpz D{D:g}",
                               damage_threshold=damage_threshold)
    sets = {"one size": [curves[reference]],
            "three sizes": [curves[D] for D in sizes],
            "local only": [local[reference]],
            "one size + local": [curves[reference], local[reference]],
            "all": [curves[D] for D in sizes] + [local[reference]]}
    return {name: ForwardOperator(obs, params, names, model=model) for name, obs in sets.items()}
