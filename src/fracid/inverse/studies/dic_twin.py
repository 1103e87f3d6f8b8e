"""A synthetic digital-image-correlation (DIC) twin: a forward run written as a camera would record it.

:func:`synthetic_dic` runs the forward model with a step at every frame's control value, samples the
displacement at a speckle-like cloud of subset centres that is not aligned with the mesh (a regular
grid at ``spacing``, rotated by a few degrees and jittered, the points outside the meshed face
dropped), adds a rigid-body motion of the specimen, adds spatially correlated noise
(:mod:`fracid.data.dic_noise`), makes holes (NaN) near the crack path where correlation fails, and
maps everything to the camera frame of a :class:`~fracid.data.dic.CameraPlacement`. :func:`write_dic`
writes the per-frame
CSV point clouds and the frame table in the DIC export format of fracid (issue 27):

* ``frame_0001.csv`` ...: columns ``X, Y, U, V, sigma`` (camera frame, ``coordinate_unit``), the same
  points in the same order in every frame, a hole a ``NaN`` displacement;
* ``frames.csv``: ``frame, file, <control>_mm, force_N`` (e.g. ``cmod_mm``) of every frame.

The points are in the modelled part of the specimen (a symmetric half or quarter), or on both halves of a
half modelled about its crack line (``both_halves``: the other half is the mirror image). Units: mm and N; camera units are px or mm (the placement's scale says which).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fracid.data.dic.placement import CameraPlacement, rotation_matrix
from fracid.data.dic_noise import dic_covariance
from fracid.inverse.core.field_observations import mirrored_points
from fracid.inverse.experiments.crack_region import crack_distance
from fracid.specimens.description import Description

#: relative tolerance of the point-in-element test (the probe operator has the final word)
_INSIDE_TOL = 1e-9


@dataclass(frozen=True)
class SyntheticDic:
    """Synthetic DIC data in memory (what :func:`write_dic` writes, and the truth behind it).

    Attributes
    ----------
    X : ndarray, shape (n, 2)
        Subset centres in the camera frame [camera unit].
    U : ndarray, shape (n_frames, n, 2)
        Displacements in the camera frame [camera unit], NaN at the holes.
    sigma : float
        Displacement std per point and component [camera unit].
    control_name : str
        The run's control (e.g. ``"cmod"``).
    control, force : ndarray, shape (n_frames,)
        The control [mm] and force [N] of each frame, from the run.
    placement : fracid.data.dic.CameraPlacement
    points : ndarray, shape (n, 2)
        The subset centres in specimen coordinates [mm].
    holes : ndarray of bool, shape (n,)
        The points with no displacement (NaN).
    noise : ndarray, shape (n_frames, n, 2)
        The noise added, in specimen components [mm].
    rigid_body : ndarray, shape (n_frames, 3)
        (tx [mm], ty [mm], theta [rad]) of each frame.
    """

    X: np.ndarray
    U: np.ndarray
    sigma: float
    control_name: str
    control: np.ndarray
    force: np.ndarray
    placement: CameraPlacement
    points: np.ndarray
    holes: np.ndarray
    noise: np.ndarray
    rigid_body: np.ndarray


def speckle_grid(low, high, spacing: float, *, angle: float = np.radians(3.0), jitter: float = 0.15,
                 rng=None) -> np.ndarray:
    """A regular grid at ``spacing`` [mm] covering the box [low, high], rotated by ``angle`` [rad]
    about the box's centre and jittered by a uniform +- ``jitter`` spacing per coordinate."""
    if not (np.isfinite(spacing) and spacing > 0):
        raise ValueError(f"spacing = {spacing!r}; give the distance between DIC points > 0 [mm]")
    if not 0.0 <= jitter < 0.5:
        raise ValueError(f"jitter = {jitter!r}; give a fraction of the spacing in [0, 0.5)")
    rng = np.random.default_rng(rng)
    low, high = np.asarray(low, float), np.asarray(high, float)
    centre, radius = 0.5 * (low + high), 0.5 * np.linalg.norm(high - low) + spacing
    ticks = np.arange(-radius, radius + 1e-12, spacing)
    grid = np.stack(np.meshgrid(ticks, ticks, indexing="ij"), axis=-1).reshape(-1, 2)
    grid = grid @ rotation_matrix(angle).T + centre + rng.uniform(-jitter, jitter, grid.shape) * spacing
    return grid[np.all((grid >= low) & (grid <= high), axis=1)]


def inside_mesh(nodes, corners, points, *, chunk: int = 256) -> np.ndarray:
    """Whether each point lies in one of the straight-sided elements of corner nodes ``corners``
    (n_el, 3 or 4, in order around the element), by the signs of the edge cross products."""
    X = np.asarray(nodes, float)[np.asarray(corners)]  # (n_el, m, 2)
    edges = np.roll(X, -1, axis=1) - X
    size = np.ptp(X.reshape(-1, 2), axis=0).max()
    inside = np.zeros(len(points), dtype=bool)
    for start in range(0, len(points), chunk):
        p = np.asarray(points[start:start + chunk], float)[:, None, None, :]  # (c, 1, 1, 2)
        rel = p - X[None]
        cross = edges[None, ..., 0] * rel[..., 1] - edges[None, ..., 1] * rel[..., 0]  # (c, n_el, m)
        tol = _INSIDE_TOL * size**2
        hit = np.all(cross >= -tol, axis=2) | np.all(cross <= tol, axis=2)
        inside[start:start + chunk] = hit.any(axis=1)
    return inside


def _rigid_body(rigid_body, n_frames: int) -> np.ndarray:
    rb = np.asarray(rigid_body, float)
    if rb.shape == (3,):
        rb = np.tile(rb, (n_frames, 1))
    if rb.shape != (n_frames, 3) or not np.all(np.isfinite(rb)):
        raise ValueError(f"rigid_body has shape {rb.shape}; give (tx [mm], ty [mm], theta [rad]) or one such row "
                         f"per frame, shape ({n_frames}, 3), finite")
    return rb


def rigid_motion(points, tx: float, ty: float, theta: float) -> np.ndarray:
    """Displacement [mm] of a rigid motion at ``points``: rotation by theta about the specimen's origin,
    then the translation (tx, ty): u = (R(theta) - I) x + t."""
    points = np.asarray(points, float)
    return points @ (rotation_matrix(theta) - np.eye(2)).T + np.array([tx, ty])


def _frame_fields(run, frames) -> list:
    """The nodal displacement of the run at each frame's control value (a step of the run)."""
    out = []
    for f in frames:
        step = int(np.argmin(np.abs(run.control - f)))
        if abs(run.control[step] - f) > 1e-9 * max(abs(f), 1e-12) or step not in run.fields:
            raise ValueError(f"frame at {run.control_name} = {f:.6g} mm was not reached by the run (it ended at "
                             f"{run.control[-1]:.6g} mm: {run.status}); give frames within the run's range")
        out.append((step, np.asarray(run.fields[step]["u"], float)))
    return out


def _check_frames(frames) -> np.ndarray:
    frames = np.asarray(frames, float)
    if frames.ndim != 1 or frames.size == 0 or not np.all(np.isfinite(frames)) or np.any(frames <= 0) or np.any(
            np.diff(frames) <= 0):
        raise ValueError(f"frames = {frames!r}; give increasing control values > 0 [mm], one per frame")
    return frames


def synthetic_dic(specimen, params, *, model=None, frames, spacing: float, std: float, subset_size: float,
                  holes: float | None = None, hole_span=None, rigid_body=(0.0, 0.0, 0.0),
                  placement: CameraPlacement = CameraPlacement(1.0), grid_angle: float = np.radians(3.0),
                  jitter: float = 0.15, both_halves: bool = False,
                  seed: int = 0, **options) -> SyntheticDic:
    """Synthetic DIC data of a forward run at ``params``.

    Parameters
    ----------
    specimen, params, model
        As :func:`fracid.models.forward.simulate` (the gradient damage model if ``model`` is None).
    frames : array_like
        Increasing control values of the frames [mm] (e.g. CMOD); each is a step of the run.
    spacing : float
        Distance between neighbouring subset centres [mm].
    std : float
        Displacement noise std per point and component [mm] (1e-3: 1 micrometre); 0: no noise.
    subset_size : float
        DIC subset size [mm]; the noise correlation length is subset_size / 2 (:mod:`fracid.data.dic_noise`).
    holes : float, optional
        Points closer than this to the crack line over ``hole_span`` have NaN displacements [mm].
    hole_span : (float, float), optional
        See :func:`crack_distance`.
    rigid_body : (tx, ty, theta) or array_like, shape (n_frames, 3)
        Rigid motion of the specimen [mm, mm, rad] added at each frame (:func:`rigid_motion`).
    placement : fracid.data.dic.CameraPlacement
        The camera frame on the specimen; the data are returned in camera coordinates.
    grid_angle, jitter
        The grid's rotation [rad] and jitter [fraction of spacing] (:func:`speckle_grid`).
    both_halves : bool
        For a specimen modelled as a symmetric half about its crack line (``Description.crack.mirrored``): the
        camera sees both halves (the other half's displacements are the mirror image's, as
        :class:`~fracid.inverse.core.field_observations.FieldObservation` computes them). Default: the modelled part.
    seed : int
        Seeds the jitter and the noise.
    **options
        Further options of the run (e.g. ``steps``).

    Returns
    -------
    SyntheticDic
    """
    from fracid.models.forward import check_specimen, simulate
    from fracid.models import probe_matrix

    frames = _check_frames(frames)
    if not (np.isfinite(std) and std >= 0):
        raise ValueError(f"std = {std!r}; give the displacement noise std >= 0 [mm]")
    rb = _rigid_body(rigid_body, len(frames))
    check_specimen(specimen, model)
    d = specimen.describe()
    if d.dim != 2:
        raise ValueError(f"DIC needs a plane specimen; {type(specimen).__name__} is {d.dim}D")
    rng = np.random.default_rng(seed)
    low, high = _face(d, both_halves)
    grid = speckle_grid(low, high, spacing, angle=grid_angle, jitter=jitter, rng=rng)
    sampled, sign = mirrored_points(d, grid)
    inside = inside_mesh(d.nodes, d.corners, sampled)
    points, sampled = grid[inside], sampled[inside]
    sign = np.column_stack([sign[0][inside], sign[1][inside]])
    P = probe_matrix(d.nodes, d.cells, sampled)  # raises for a point outside the mesh
    run = simulate(specimen, params, model=model, target=float(frames[-1]), checkpoints=frames, field_steps="all",
                   **options)
    steps = _frame_fields(run, frames)
    u = np.stack([(P @ q.reshape(-1, 2)) * sign for _, q in steps])  # (n_frames, n, 2) [mm]
    u = u + np.stack([rigid_motion(points, *row) for row in rb])
    noise = _noise(points, std, subset_size, len(frames), rng)
    hole = np.zeros(len(points), bool) if holes is None else crack_distance(d, points, hole_span) < holes
    U = placement.displacements_to_camera(u + noise)
    U[:, hole] = np.nan
    index = [s for s, _ in steps]
    return SyntheticDic(X=placement.to_camera(points), U=U, sigma=std / placement.scale, control_name=run.control_name,
                   control=run.control[index], force=run.force[index], placement=placement, points=points,
                   holes=hole, noise=noise, rigid_body=rb)


def _face(description: Description, both_halves: bool) -> tuple[np.ndarray, np.ndarray]:
    """The box [mm] the camera sees: the mesh's, and with ``both_halves`` its mirror across the crack line too."""
    low, high = description.nodes.min(axis=0), description.nodes.max(axis=0)
    if not both_halves:
        return low, high
    crack = description.crack
    if crack is None or crack.nodes is None or not crack.mirrored:
        raise ValueError("both_halves needs a specimen modelled as a symmetric half about its crack line "
                         "(Description.crack.mirrored); this one is not")
    from fracid.specimens.crack_line import crack_line

    corners = crack_line(description).mirror(np.array([low, high]))
    return np.minimum(low, corners.min(axis=0)), np.maximum(high, corners.max(axis=0))


def _noise(points, std: float, subset_size: float, n_frames: int, rng) -> np.ndarray:
    """Correlated noise (n_frames, n, 2) [mm], frames and components independent."""
    if std == 0:
        return np.zeros((n_frames, len(points), 2))
    C = dic_covariance(points, std, subset_size)
    draws = C.color(rng.standard_normal((len(points), 2 * n_frames)))  # (n, 2 n_frames)
    return draws.T.reshape(n_frames, 2, len(points)).transpose(0, 2, 1)


def write_dic(directory, data: SyntheticDic, *, digits: int = 10) -> list[Path]:
    """Write ``data`` as per-frame CSV point clouds and ``frames.csv`` in ``directory`` (created).

    Parameters
    ----------
    directory : path
        Output directory.
    data : SyntheticDic
        From :func:`synthetic_dic`.
    digits : int
        Significant digits of the numbers written.

    Returns
    -------
    list of Path
        The files written, the frame table last.
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    number = f"{{:.{int(digits)}g}}".format
    cell = lambda v: "NaN" if not np.isfinite(v) else number(v)  # noqa: E731
    written, table = [], []
    for k in range(len(data.U)):
        name = f"frame_{k + 1:04d}.csv"
        with open(directory / name, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["X", "Y", "U", "V", "sigma"])
            for (x, y), (u, v) in zip(data.X, data.U[k]):
                w.writerow([cell(x), cell(y), cell(u), cell(v), cell(data.sigma)])
        written.append(directory / name)
        table.append([k + 1, name, cell(data.control[k]), cell(data.force[k])])
    with open(directory / "frames.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["frame", "file", f"{data.control_name}_mm", "force_N"])
        w.writerows(table)
    return written + [directory / "frames.csv"]


__all__ = ["SyntheticDic", "inside_mesh", "rigid_motion", "speckle_grid", "synthetic_dic",
           "write_dic"]
