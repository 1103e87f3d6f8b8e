"""Experimental data: measured curves read from files, and the vector y_exp with its covariance C_exp.

Units: control quantities in mm, forces in N.

>>> from fracid.data import gregoire2013_beam4
>>> data = gregoire2013_beam4(n_points=40)
>>> data.y.shape, data.covariance.shape
((40,), (40, 40))
"""

from fracid.data.curves import (
    Curve,
    DataError,
    DataTypeError,
    curve_from_arrays,
    read_curve_csv,
    require_positive_force,
)
from fracid.data.covariance_matrix import (
    Block,
    Covariance,
    Dense,
    Diagonal,
    LowRankPlusDiagonal,
    as_covariance,
    block_diagonal,
)
from fracid.data.dataset import ExperimentalData, stack
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
