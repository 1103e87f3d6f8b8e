"""DIC design study (fracid issue 27): which DIC set-up decorrelates beta and c? Linearised posterior at the truth.

The demo's notched beam (Grégoire geometry, half model, gradient damage), (kappa_i, beta, c) at the truth
(``--truth demo``: the demo's estimate of benchmarks/dic_identification.py; ``--truth example``: the parameters
of examples/dic/make_data.py, beta 600, c 9). ONE forward run with direct differentiation gives the exact
sensitivities of the force-CMOD curve (12 points in [0.01, 0.2] mm, std 1 % of the peak force, as
benchmarks/dic_identification.py) and of the displacement field u, v at every point of several speckle-like
grids (:func:`fracid.inverse.studies.dic_twin.speckle_grid`, the points of synthetic_dic at the same seed) and
every frame of a dense CMOD set (every 0.0025 mm up to 0.2 mm, plus the frames of the benchmark and of the
example). Every DIC set-up is a selection of these rows (grid spacing, frames, components, points away from
the crack: the ``exclude_near`` of the configuration) with its own covariance: per frame and component std^2
times fracid's Gaussian kernel (:func:`fracid.data.dic_noise.dic_kernel`, l = subset / 2) plus fracid's
diagonal floor (1e-3 std^2), factored exactly (dense Cholesky); frames and components independent; optionally
the rigid motion (t_x, t_y, theta) of every frame marginalised as :func:`fracid.data.dic.field_block` does with
``rigid_std`` 1 mm (:func:`fracid.data.dic.rigid.rigid_modes`, Woodbury). ``--cov fracid`` uses fracid's own
low-rank-plus-diagonal :func:`fracid.data.dic.field.field_covariance` instead (Nystrom beyond 2500 points);
``--kernel tent`` the overlap of square subsets as the correlation; ``--frame-rho`` errors shared between frames
(a common reference image); ``--nugget`` the independent part. The posterior is
C_post = (S^T C^-1 S + C0^-1)^-1, C0 the uniform prior over the demo's bounds.

Printed:

1. the wall time of the run with sensitivities (and of the curve-alone run), the load average;
2. the table: per set-up, points, frames, values, then without / with the rigid motion marginalised:
   r(beta, c), r(kappa_i, c) and the posterior stds [% of the truth] of (kappa_i, beta, c), and r(beta, c) of
   the field alone (with C0), and the std of the worst-determined relative combination; first the curve alone;
3. for the reference set-ups: the Fisher information of each frame and of bands of points at a distance from
   the crack, along the weak (beta, c) direction of the curve (see :func:`insight`);
4. a JSON line with everything.

    python benchmarks/dic_design.py [--h-fine 2] [--truth demo|example] [--kernel gauss|tent] [--frame-rho 0]
        [--nugget 1e-3] [--cov exact|fracid] [--rows 0,1,...] [--quick] [--json out.json]
    python benchmarks/dic_design.py --setup --spacing 1.0 --frames every:0.005 --components uv \
        --exclude 2.0 --std 1e-3 --subset 2.0        # one custom set-up (frames: every:STEP or a list)

``--quick`` evaluates a few rows only. The run with sensitivities takes ~6 s at h_fine 2 (~13 s at h_fine 1),
the whole table ~1 min (docs/dic/design.md has the results and the conclusion).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import time

import numpy as np
import scipy.linalg
from scipy.spatial.distance import cdist

from fracid.data.dic.field import field_covariance
from fracid.data.dic.rigid import prior_scales, rigid_modes
from fracid.data.dic_noise import DIAGONAL_FLOOR, dic_kernel
from fracid.fem.material.parameters import DamageParameters
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.field_observations import FieldObservation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.experiments.crack_region import crack_distance
from fracid.inverse.studies.dic_twin import inside_mesh, speckle_grid
from fracid.inverse.studies.uniqueness import bounds_covariance
from fracid.specimens.beam import NotchedBeam

BASE = DamageParameters(E=36250.0, nu=0.2, kappa_i=6.6e-5, alpha=0.99, beta=600.0, c=9.0, eta=10.0)  # demo.toml
NAMES = ("kappa_i", "beta", "c")
TRUTHS = {"demo": np.array([4.798e-5, 1086.5, 21.46]),  # benchmarks/dic_identification.py TRUTH
          "example": np.array([6.6e-5, 600.0, 9.0])}  # examples/dic/make_data.py PARAMS
SPACE = ParameterSpace(NAMES, [4e-5, 200.0, 4.0], [1e-4, 3000.0, 30.0], log=(False, True, False))
CURVE = np.linspace(0.01, 0.2, 12)  # CMOD [mm]
CURVE_STD = 0.01  # of the peak force
SPACINGS = (3.5, 3.8, 2.0, 1.0, 0.75)  # mm: the grids computed in the run
SEED = 5  # the benchmark's: its 3.5 mm grid is synthetic_dic's (359 points)
RIGID_STD = 1.0  # mm

#: frame sets [mm of CMOD]
FRAME_SETS = {
    "bench6": np.linspace(0.025, 0.2, 6),  # benchmarks/dic_identification.py
    "example6": np.array([0.02, 0.034, 0.05, 0.08, 0.12, 0.2]),  # examples/dic/make_data.py
    "soft12": np.array([0.02, 0.034, 0.05, 0.065, 0.08, 0.095, 0.11, 0.125, 0.14, 0.16, 0.18, 0.2]),
    "every:0.01": np.round(np.arange(0.01, 0.2001, 0.01), 6),
    "every:0.005": np.round(np.arange(0.005, 0.2001, 0.005), 6),
    "every:0.0025": np.round(np.arange(0.0025, 0.2001, 0.0025), 6),
    "prepeak": np.array([0.01, 0.02, 0.03]),
    "softonly": np.round(np.arange(0.05, 0.2001, 0.01), 6),
}
DENSE = np.unique(np.concatenate(list(FRAME_SETS.values()) + [[0.034]]).round(6))


@dataclasses.dataclass(frozen=True)
class Setup:
    """One DIC set-up: grid spacing [mm], frame set (name in FRAME_SETS), components, points nearer the crack
    path than ``exclude`` [mm] dropped (the config's exclude_near), noise std [mm], subset size [mm]."""

    label: str
    spacing: float = 3.5
    frames: str = "bench6"
    components: str = "uv"
    exclude: float = 0.0
    std: float = 1e-3
    subset: float = 6.0


def frames_of(name: str) -> np.ndarray:
    if name in FRAME_SETS:
        return FRAME_SETS[name]
    if name.startswith("every:"):
        return np.round(np.arange(float(name[6:]), 0.2001, float(name[6:])), 6)
    return np.array([float(v) for v in name.split(",")])


def kernel(points, subset: float, kind: str) -> np.ndarray:
    """The correlation of one displacement component between the points: ``gauss`` fracid's model
    (:func:`fracid.data.dic_noise.dic_kernel`, exp(-d^2 / (2 l^2)), l = subset / 2), or ``tent`` the overlap
    fraction of two square subsets (1 - |dx| / s)+ (1 - |dy| / s)+, the correlation of subset-averaged white
    image noise."""
    if kind == "gauss":
        return dic_kernel(points, points, 1.0, subset)
    K = np.clip(1.0 - cdist(points[:, :1], points[:, :1], "cityblock") / subset, 0.0, None)
    K *= np.clip(1.0 - cdist(points[:, 1:], points[:, 1:], "cityblock") / subset, 0.0, None)
    return K


def correlations(C) -> np.ndarray:
    s = np.sqrt(np.diag(C))
    return C / np.outer(s, s)


def weak_std(P, truth) -> float:
    """The std [%] of the worst-determined combination of the relative parameters (dx / truth): the square root
    of the largest eigenvalue of the relative posterior covariance."""
    T = np.diag(1.0 / truth)
    return float(100 * np.sqrt(np.linalg.eigvalsh(T @ P @ T)[-1]))


class Study:
    """The run at the truth (sensitivities of the curve and of every grid at every dense frame) and the
    posterior of any set-up."""

    def __init__(self, h_fine: float, truth: np.ndarray, spacings=SPACINGS, cov: str = "exact",
                 kernel: str = "gauss", nugget: float = DIAGONAL_FLOOR, rho: float = 0.0):
        self.cov, self.kernel, self.nugget, self.rho = cov, kernel, nugget, rho
        self.beam = NotchedBeam(h_fine=h_fine, h_coarse=6.0)
        self.truth = truth
        d = self.beam.describe()
        self.description = d
        self.grids = {}
        for s in spacings:
            g = speckle_grid(d.nodes.min(axis=0), d.nodes.max(axis=0), s, angle=np.radians(3.0), jitter=0.15,
                             rng=np.random.default_rng(SEED))
            self.grids[s] = g[inside_mesh(d.nodes, d.corners, g)]
        line = d.nodes[d.nodes_of(d.crack.nodes)]
        along = 1 - d.crack.normal
        self.span = (float(d.nodes[:, along].min()), float(line[:, along].max()))  # as exclude_near
        curve = Observation(self.beam, CURVE, control="cmod", name="curve")
        fields = [FieldObservation(self.beam, p, DENSE, control="cmod", name=f"grid{s}") for s, p in self.grids.items()]
        op = ForwardOperator([curve, *fields], BASE, NAMES).differentiated()
        start = time.perf_counter()
        record = op(truth)
        self.seconds = time.perf_counter() - start
        assert record.ok, record.error
        start = time.perf_counter()
        ForwardOperator([curve], BASE, NAMES).differentiated()(truth)
        self.seconds_curve = time.perf_counter() - start
        n = CURVE.size
        self.S_curve = record.S[:n]
        self.F_curve = self.S_curve.T @ (self.S_curve / (CURVE_STD * record.y[:n].max()) ** 2)
        self.peak = record.y[:n].max()
        self.S_field = {}  # spacing -> (n_frames, 2, n_points, 3)
        for (s, p), part in zip(self.grids.items(), op.slices()[1:]):
            self.S_field[s] = record.S[part].reshape(DENSE.size, 2, len(p), len(NAMES))
        self.prior = np.linalg.inv(bounds_covariance(SPACE))
        self._cov = {}

    def selection(self, setup: Setup, mask=None):
        """(points, S (n_frames, n_comp * n_points, 3), frames) of a set-up."""
        points = self.grids[setup.spacing]
        keep = np.ones(len(points), bool) if not setup.exclude else (
            crack_distance(self.description, points, self.span) >= setup.exclude)
        if mask is not None:
            keep &= mask(points)
        comps = {"uv": [0, 1], "u": [0], "v": [1]}[setup.components]
        frames = frames_of(setup.frames)
        fi = [int(np.argmin(np.abs(DENSE - f))) for f in frames]
        assert np.allclose(DENSE[fi], frames), frames
        S = self.S_field[setup.spacing][fi][:, comps][:, :, keep]
        return points[keep], S.reshape(len(fi), len(comps) * int(keep.sum()), len(NAMES)), frames, tuple(comps)

    def _factors(self, setup: Setup, rigid: bool, mask=None):
        """Z = L^-1 S / std (points, frames, comps, 3) and Y = L^-1 M / std (points, comps, modes) or None, L the
        Cholesky factor of one component's correlation, M the rigid modes times their prior std."""
        points, S, frames, comps = self.selection(setup, mask)
        key = (setup.spacing, setup.exclude, setup.subset, mask)
        if key not in self._cov:  # the Cholesky factor of the correlation of one component
            K = kernel(points, setup.subset, self.kernel) + self.nugget * np.eye(len(points))
            self._cov[key] = scipy.linalg.cholesky(K, lower=True, overwrite_a=True)
        L, n, nf, nc = self._cov[key], len(points), len(frames), len(comps)
        cols = S.reshape(nf, nc, n, 3).transpose(2, 0, 1, 3).reshape(n, -1)  # (points, frames * comps * 3)
        Z = scipy.linalg.solve_triangular(L, cols, lower=True).reshape(n, nf, nc, 3) / setup.std
        if not rigid:
            return Z, None
        M = (rigid_modes(points, comps) * prior_scales(points, RIGID_STD)).reshape(nc, n, 3)  # (comps, points, 3)
        M = M[:, :, np.any(M != 0.0, axis=(0, 1))]
        Y = scipy.linalg.solve_triangular(L, M.transpose(1, 0, 2).reshape(n, -1), lower=True).reshape(n, nc, -1)
        return Z, Y / setup.std

    def frame_fisher(self, setup: Setup, rigid: bool, mask=None) -> np.ndarray:
        """The Fisher information of every frame (n_frames, 3, 3), the frames' errors independent: the frames
        share the covariance of one frame (same points and components): C = std^2 K + M M^T (Woodbury)."""
        if self.cov == "fracid":
            return self._fisher_fracid(setup, rigid, mask, *self.selection(setup, mask))
        Z, Y = self._factors(setup, rigid, mask)
        F = np.einsum("ifcp,ifcq->fpq", Z, Z)
        if Y is None:
            return F
        G = np.eye(Y.shape[2]) + np.einsum("icm,icn->mn", Y, Y)  # I + M^T A^-1 M
        B = np.einsum("ifcp,icm->fpm", Z, Y)  # S^T A^-1 M per frame
        return F - np.einsum("fpm,mn,fqn->fpq", B, np.linalg.inv(G), B)

    def fisher(self, setup: Setup, rigid: bool) -> np.ndarray:
        """The Fisher information of the set-up's field (3, 3). With ``rho`` > 0 the frames' errors share a
        part rho of their variance (the noise of the common reference image): C = std^2 Sigma_t (x) K + the
        rigid motion of every frame, Sigma_t = (1 - rho) I + rho 1 1^T."""
        if self.rho == 0.0:
            return self.frame_fisher(setup, rigid).sum(axis=0)
        Z, Y = self._factors(setup, rigid)
        nf = Z.shape[1]
        Ti = (np.eye(nf) - self.rho / (1 - self.rho + nf * self.rho)) / (1 - self.rho)  # Sigma_t^-1
        ZZ = np.einsum("ifcp,igcq->fgpq", Z, Z)
        F = np.einsum("fg,fgpq->pq", Ti, ZZ)
        if Y is None:
            return F
        m = Y.shape[2]
        ZY = np.einsum("ifcp,icm->fpm", Z, Y)  # per frame S_f^T K^-1 M
        B = np.einsum("fg,fpm->pgm", Ti, ZY).reshape(3, nf * m)  # S^T A^-1 M, M block diagonal over frames
        G = np.eye(nf * m) + np.kron(Ti, np.einsum("icm,icn->mn", Y, Y))
        return F - B @ np.linalg.solve(G, B.T)

    def _fisher_fracid(self, setup, rigid, mask, points, S, frames, comps):
        """As :meth:`frame_fisher` with the covariance fracid's field_block builds (low rank + diagonal)."""
        key = ("fracid", setup.spacing, setup.exclude, setup.components, setup.std, setup.subset, rigid, mask)
        if key not in self._cov:
            sigma = np.full(len(comps) * len(points), setup.std)
            self._cov[key] = field_covariance(points, sigma, 1, comps, setup.subset, RIGID_STD if rigid else None)[0]
        C = self._cov[key]
        cols = S.transpose(1, 0, 2).reshape(S.shape[1], -1)  # (entries, frames * 3)
        W = C.solve(cols).reshape(S.shape[1], len(frames), len(NAMES)).transpose(1, 0, 2)
        return np.einsum("fip,fiq->fpq", S, W)

    def posterior(self, F_field: np.ndarray, curve: bool = True) -> np.ndarray:
        return np.linalg.inv(F_field + (self.F_curve if curve else 0.0) + self.prior)

    def row(self, setup: Setup) -> dict:
        points, S, frames, comps = self.selection(setup)
        out = {"setup": dataclasses.asdict(setup), "points": len(points), "frames": len(frames),
               "values": int(S.shape[0] * S.shape[1])}
        for rigid in (False, True):
            F = self.fisher(setup, rigid)
            P, P_field = self.posterior(F), self.posterior(F, curve=False)
            r, rf = correlations(P), correlations(P_field)
            out["rigid" if rigid else "plain"] = {
                "r_beta_c": r[1, 2], "r_kappa_c": r[0, 2], "r_kappa_beta": r[0, 1],
                "std_percent": (100 * np.sqrt(np.diag(P)) / self.truth).tolist(), "weak_std_percent": weak_std(P, self.truth),
                "field_alone_r_beta_c": rf[1, 2], "field_alone_r_kappa_c": rf[0, 2]}
        return out

    def curve_row(self) -> dict:
        P = self.posterior(np.zeros((3, 3)))
        r = correlations(P)
        return {"r_beta_c": r[1, 2], "r_kappa_c": r[0, 2], "std_percent": (100 * np.sqrt(np.diag(P)) / self.truth).tolist(),
                "weak_std_percent": weak_std(P, self.truth)}

    def weak_direction(self) -> np.ndarray:
        """The least-informed direction of the curve alone (+ prior) in relative parameters (dx / truth)."""
        T = np.diag(self.truth)
        w, V = np.linalg.eigh(T @ (self.F_curve + self.prior) @ T)
        return V[:, 0]

    def insight(self, setup: Setup, rigid: bool = True) -> dict:
        """Fisher information along the curve's weak direction v (relative parameters): v^T T F T v, per frame
        and per band of points by distance from the crack (each band alone, with its own covariance), and the
        correlation r(beta, c) of curve + that band (all frames of the set-up)."""
        T, v = np.diag(self.truth), self.weak_direction()
        along = lambda F: float(v @ T @ F @ T @ v)  # noqa: E731
        per_frame = self.frame_fisher(setup, rigid)
        out = {"weak_direction": v.tolist(), "curve": along(self.F_curve + self.prior),
               "frames": {f"{f:.4g}": along(F) for f, F in zip(frames_of(setup.frames), per_frame)}, "bands": {}}
        edges = (0, 2, 4, 8, 16, 32, 100)
        for lo, hi in zip(edges[:-1], edges[1:]):
            if hi <= setup.exclude:
                continue
            mask = _Band(self.description, self.span, lo, hi)
            try:
                F = self.frame_fisher(setup, rigid, mask).sum(axis=0)
            except Exception:  # an empty band
                continue
            out["bands"][f"{lo}-{hi} mm"] = {"along_weak": along(F),
                                             "r_beta_c_curve_plus_band": correlations(self.posterior(F))[1, 2]}
        return out


@dataclasses.dataclass(frozen=True)
class _Band:
    """Points at a distance in [lo, hi) [mm] from the crack path (hashable: a cache key)."""

    description: object
    span: tuple
    lo: float
    hi: float

    def __call__(self, points):
        d = crack_distance(self.description, points, self.span)
        return (d >= self.lo) & (d < self.hi)

    def __hash__(self):
        return hash((self.lo, self.hi))

    def __eq__(self, other):
        return isinstance(other, _Band) and (self.lo, self.hi) == (other.lo, other.hi)


def reference_setups() -> list[Setup]:
    """The rows of the table: the benchmark, one change at a time from a realistic reference, combinations."""
    ref = dict(spacing=3.8, frames="example6", components="uv", exclude=4.0, std=1e-3, subset=6.0)
    S = lambda label, **kw: Setup(label, **{**ref, **kw})  # noqa: E731
    return [
        Setup("benchmark (3.5 mm, bench6, no exclusion)", 3.5, "bench6", "uv", 0.0, 1e-3, 6.0),
        S("REF: example camera (3.8 mm, example6, excl 4, 1 um, subset 6)"),
        S("ref, no exclusion", exclude=0.0),
        S("spacing 2", spacing=2.0),
        S("spacing 1", spacing=1.0),
        S("frames soft12", frames="soft12"),
        S("frames every 0.01 (20)", frames="every:0.01"),
        S("frames every 0.005 (40)", frames="every:0.005"),
        S("frames every 0.0025 (80)", frames="every:0.0025"),
        S("frames pre-peak only (3)", frames="prepeak"),
        S("frames softening only (16)", frames="softonly"),
        S("u only", components="u"),
        S("v only", components="v"),
        S("exclusion 2 mm", exclude=2.0),
        S("std 0.5 um", std=5e-4),
        S("subset 3 mm", subset=3.0),
        S("subset 1.5 mm", subset=1.5),
        S("spacing 2, subset 4 (step ~ half subset)", spacing=2.0, subset=4.0),
        S("spacing 1, subset 2", spacing=1.0, subset=2.0),
        S("spacing 0.75, subset 1.5", spacing=0.75, subset=1.5),
        S("spacing 1, subset 2, every 0.005", spacing=1.0, subset=2.0, frames="every:0.005"),
        S("spacing 1, subset 2, every 0.005, excl 2", spacing=1.0, subset=2.0, frames="every:0.005", exclude=2.0),
        S("spacing 0.75, subset 1.5, every 0.005", spacing=0.75, subset=1.5, frames="every:0.005"),
        S("spacing 0.75, subset 1.5, every 0.005, excl 2", spacing=0.75, subset=1.5, frames="every:0.005",
          exclude=2.0),
        S("spacing 0.75, subset 1.5, every 0.005, 0.5 um", spacing=0.75, subset=1.5, frames="every:0.005", std=5e-4),
        S("spacing 2, subset 4, every 0.005", spacing=2.0, subset=4.0, frames="every:0.005"),
        S("spacing 2, subset 4, every 0.005, excl 2", spacing=2.0, subset=4.0, frames="every:0.005", exclude=2.0),
        S("spacing 3.8, subset 6, every 0.005, excl 2", frames="every:0.005", exclude=2.0),
        S("spacing 0.75, subset 1.5, every 0.0025 (80)", spacing=0.75, subset=1.5, frames="every:0.0025"),
        S("spacing 0.75, subset 1.5, every 0.005, excl 1", spacing=0.75, subset=1.5, frames="every:0.005",
          exclude=1.0),
        S("spacing 0.75, subset 1.5, every 0.005, NO excl (unreal)", spacing=0.75, subset=1.5,
          frames="every:0.005", exclude=0.0),
    ]


def reference_setups_index(setup: Setup) -> int:
    return [s.label for s in reference_setups()].index(setup.label)


QUICK = (0, 1, 7, 19, 22)  # rows of --quick
INSIGHT = (1, 22, 30)  # rows whose per-frame / per-band information is printed


def fmt(row) -> str:
    def part(p):
        s = p["std_percent"]
        return (f"{p['r_beta_c']:6.3f} {p['r_kappa_c']:6.3f} {s[0]:5.2f} {s[1]:5.2f} {s[2]:5.2f} "
                f"{p['weak_std_percent']:5.2f} {p['field_alone_r_beta_c']:6.3f}")
    return f"{row['points']:5d} {row['frames']:3d} {row['values']:7d} | {part(row['plain'])} | {part(row['rigid'])}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h-fine", type=float, default=2.0)
    parser.add_argument("--truth", choices=sorted(TRUTHS), default="demo")
    parser.add_argument("--quick", action="store_true", help="the reference rows only")
    parser.add_argument("--json", default=None, help="write the results to this file")
    parser.add_argument("--cov", choices=("exact", "fracid"), default="exact",
                        help="exact: the dense kernel (Cholesky) + nugget, rigid motion by Woodbury; fracid: "
                             "field_covariance's low rank + diagonal (Nystrom beyond 2500 points)")
    parser.add_argument("--kernel", choices=("gauss", "tent"), default="gauss", help="noise correlation (exact)")
    parser.add_argument("--nugget", type=float, default=DIAGONAL_FLOOR,
                        help="independent part of the variance added to the correlation (exact)")
    parser.add_argument("--frame-rho", type=float, default=0.0,
                        help="correlation of the errors of different frames (a common reference image: ~0.5)")
    parser.add_argument("--rows", default=None, help="comma-separated row numbers of the table to evaluate")
    parser.add_argument("--setup", action="store_true", help="evaluate one custom set-up (options below)")
    parser.add_argument("--spacing", type=float, default=3.8, choices=SPACINGS)
    parser.add_argument("--frames", default="example6", help=f"{sorted(FRAME_SETS)}, every:STEP or a list a,b,c")
    parser.add_argument("--components", default="uv", choices=("uv", "u", "v"))
    parser.add_argument("--exclude", type=float, default=4.0, help="mm: points nearer the crack path dropped")
    parser.add_argument("--std", type=float, default=1e-3, help="mm")
    parser.add_argument("--subset", type=float, default=6.0, help="mm")
    args = parser.parse_args(argv)
    load_before = os.getloadavg()
    truth = TRUTHS[args.truth]
    spacings = (args.spacing,) if args.setup else SPACINGS
    if args.setup:  # the run computes this set-up's frames only: its wall time is the set-up's
        globals()["DENSE"] = frames_of(args.frames)
    study = Study(args.h_fine, truth, spacings, args.cov, args.kernel, args.nugget, args.frame_rho)
    print(f"h_fine {args.h_fine}, truth {args.truth} {truth.tolist()}: run with sensitivities (curve + "
          f"{sum(len(p) for p in study.grids.values())} points x 2 x {DENSE.size} frames) {study.seconds:.1f} s, "
          f"curve alone {study.seconds_curve:.1f} s; peak force {study.peak:.0f} N")
    setups = ([Setup("custom", args.spacing, args.frames, args.components, args.exclude, args.std, args.subset)]
              if args.setup else [s for k, s in enumerate(reference_setups()) if (not args.quick or k in QUICK) and
                                  (args.rows is None or k in [int(v) for v in args.rows.split(",")])])
    c = study.curve_row()
    print(f"covariance {args.cov}" + (f", kernel {args.kernel}, nugget {args.nugget:g}" if args.cov == "exact" else "") +
          f", frame-to-frame error correlation {args.frame_rho:g}")
    print(f"{'set-up':62s} {'pts':>5s} {'frm':>3s} {'values':>7s} | no rigid: r(b,c) r(k,c) std% k b c weak "
          f"field-alone r(b,c) | rigid marginalised: idem")
    print(f"{'curve alone':62s} {'':17s} | {c['r_beta_c']:6.3f} {c['r_kappa_c']:6.3f} {c['std_percent'][0]:5.2f} "
          f"{c['std_percent'][1]:5.2f} {c['std_percent'][2]:5.2f} {c['weak_std_percent']:5.2f}")
    k_of = {id(s): (0 if args.setup else reference_setups_index(s)) for s in setups}
    rows = []
    start = time.perf_counter()
    for s in setups:
        row = study.row(s)
        rows.append(row)
        print(f"{k_of[id(s)]:2d} {s.label[:59]:59s} {fmt(row)}", flush=True)
    table_s = time.perf_counter() - start
    insights = {}
    for k in ((0,) if args.setup else INSIGHT):
        if k < len(setups):
            ins = study.insight(setups[k])
            insights[setups[k].label] = ins
            print(f"\ninformation along the curve's weak direction v = {np.round(ins['weak_direction'], 3).tolist()} "
                  f"(relative kappa_i, beta, c), rigid marginalised, {setups[k].label}: curve + prior {ins['curve']:.3g}")
            print("  per frame (CMOD mm: info): " + ", ".join(f"{f}: {v:.3g}" for f, v in ins["frames"].items()))
            print("  per band of distance from the crack (alone): " + ", ".join(
                f"{b}: {v['along_weak']:.3g} (r(b,c) curve+band {v['r_beta_c_curve_plus_band']:.3f})"
                for b, v in ins["bands"].items()))
    out = {"h_fine": args.h_fine, "truth": args.truth, "cov": args.cov, "kernel": args.kernel, "nugget": args.nugget, "frame_rho": args.frame_rho, "truth_values": truth.tolist(), "run_s": study.seconds,
           "curve_run_s": study.seconds_curve, "table_s": table_s, "points": {str(s): len(p) for s, p in study.grids.items()},
           "dense_frames": DENSE.size, "curve": c, "rows": rows, "insight": insights, "loadavg_before": load_before,
           "loadavg_after": os.getloadavg()}
    print(f"\ntable {table_s:.0f} s; load average {load_before} -> {out['loadavg_after']}")
    text = json.dumps(out, default=float)
    if args.json:
        with open(args.json, "w") as f:
            f.write(text)
    print(text)
    return out


if __name__ == "__main__":
    main()
