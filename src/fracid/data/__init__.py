"""Experimental data: measured curves read from files, and the vector y_exp with its covariance C_exp.

Units: control quantities in mm, forces in N. The bundled data sets (files, READMEs, licences and their
configurations) live in :mod:`fracid.datasets`, the one home and loader of bundled data.

>>> from fracid import datasets
>>> from fracid.data import from_envelope, read_curve_csv
>>> curves = read_curve_csv(datasets.path("gregoire2013-beam4"), control_column="cmod_mm",
...                         force_columns=["load_mean_N", "load_min_N", "load_max_N"])
>>> data = from_envelope(*curves, n_points=40, rule="range/4")
>>> data.y.shape, data.covariance.shape
((40,), (40, 40))

May import :mod:`fracid.settings` and :mod:`fracid.fem` (floor 0) and :mod:`fracid.specimens` (floor 1);
never the models' registry, the inverse methods, the configuration, the report, the command or
:mod:`fracid.datasets`.
"""

from fracid.data.checks import require_positive_force
from fracid.data.curves import Curve, curve_from_arrays, read_curve_csv
from fracid.data.covariance_matrix import Block, Covariance, Dense, Diagonal, as_covariance, block_diagonal
from fracid.data.covariance_low_rank import LowRankPlusDiagonal
from fracid.data.covariance_sparse import SparseCovariance
from fracid.data.dataset import ExperimentalData, stack
from fracid.data.errors import DataError, DataTypeError
from fracid.data.dic import CameraPlacement, DicData, fit_placement, read_dic_frames, read_dic_vtk
from fracid.data.experimental import (
    from_envelope,
    from_repeats,
    gregoire2013_beam4,
    gregoire2013_beam4_path,
    local_block,
    with_std,
)
from fracid.data.sampling import SAMPLINGS, decimate, sample_points

__all__ = [
    "Block",
    "CameraPlacement",
    "Covariance",
    "Curve",
    "DataError",
    "DataTypeError",
    "Dense",
    "DicData",
    "Diagonal",
    "ExperimentalData",
    "LowRankPlusDiagonal",
    "SparseCovariance",
    "SAMPLINGS",
    "as_covariance",
    "block_diagonal",
    "curve_from_arrays",
    "decimate",
    "fit_placement",
    "from_envelope",
    "from_repeats",
    "gregoire2013_beam4",
    "gregoire2013_beam4_path",
    "local_block",
    "read_curve_csv",
    "read_dic_frames",
    "read_dic_vtk",
    "require_positive_force",
    "sample_points",
    "stack",
    "with_std",
]
