"""Measured test curves bundled with fracid, by name: cited, licence-checked, each with a configuration that runs.

Every data set has a folder here with a README (source repository, path and commit; licence; citation;
geometry; units; what the scatter is) and the source's licence text; its data file(s) and its default
configuration, which ``fracid identify`` runs as written (the data file named relative to it). This is the
one home of bundled data and this module its one loader: the Grégoire beam's configuration is the demo's
(``fracid demo``, :func:`fracid.cli.common.demo_config_path`).

>>> from fracid import datasets
>>> datasets.names()
['gregoire2013-beam4', 'tinloi-que-wst']
>>> data = datasets.load("tinloi-que-wst")        # ExperimentalData: opening [mm], splitting force [N]

On the command line: ``fracid datasets`` lists them, ``fracid init --dataset NAME -o FILE`` writes the
configuration with the data file and the licence copied beside it (:mod:`fracid.cli.datasets`).

May import every package below the command (:func:`load` reads a data set through :mod:`fracid.config`);
only the command imports it.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

from fracid.data.errors import DataError

if TYPE_CHECKING:
    from fracid.data.dataset import ExperimentalData

__all__ = ["DATASETS", "Dataset", "UnknownDataset", "get", "load", "names", "path"]


class UnknownDataset(DataError):
    """A data set name that is not in :data:`DATASETS` (the message lists the known names)."""


def _resource(relative: str) -> Path:
    """The installed file ``relative`` to the ``fracid`` package; DataError if it was not installed."""
    found = resources.files("fracid")
    for part in relative.split("/"):
        found = found / part
    found = Path(str(found))
    if not found.is_file():
        raise DataError(f"bundled data file missing: {found}; the package data of fracid was not installed "
                        "(pyproject [tool.setuptools.package-data])")
    return found


@dataclass(frozen=True)
class Dataset:
    """One bundled data set: what it is, where it comes from, and its files.

    Parameters
    ----------
    name : str
        The name it is loaded by (``fracid init --dataset NAME``).
    title : str
        What was tested, on one line.
    citation : str
        The publication to cite, on one line.
    licence : str
        The licence of the files and the repository they come from, on one line (the copyright holders:
        the licence text, ``licence_file``).
    specimen : str
        The fracid specimen type of the configuration (:data:`fracid.specimens.SPECIMENS`).
    model : str
        The model type the configuration identifies (:data:`fracid.models.MODEL_TYPES`): a suggestion.
    folder : str
        Its folder, relative to the ``fracid`` package: README.md and the licence text.
    licence_file : str
        The source's licence text, relative to the ``fracid`` package.
    config : str
        The default configuration (TOML), relative to the ``fracid`` package.
    files : tuple of str
        The data files the configuration reads, relative to the ``fracid`` package, in the
        configuration's directory (it names them by their file name alone).
    """

    name: str
    title: str
    citation: str
    licence: str
    specimen: str
    model: str
    folder: str
    licence_file: str
    config: str
    files: tuple[str, ...]

    @property
    def readme_path(self) -> Path:
        """The installed README.md."""
        return _resource(f"{self.folder}/README.md")

    @property
    def config_path(self) -> Path:
        """The installed default configuration."""
        return _resource(self.config)

    @property
    def licence_path(self) -> Path:
        """The installed licence text of the source."""
        return _resource(self.licence_file)

    @property
    def file_paths(self) -> tuple[Path, ...]:
        """The installed data files."""
        return tuple(_resource(file) for file in self.files)


#: the bundled data sets by name (README.md, "Data sets by name")
DATASETS = {ds.name: ds for ds in (
    Dataset(name="gregoire2013-beam4",
            title="notched concrete beam in three-point bending, D = 50 mm: load vs CMOD, mean and min/max envelope",
            citation="Gregoire, Rojas-Solano & Pijaudier-Cabot (2013), Int. J. Numer. Anal. Meth. Geomech. "
                     "37(10):1434-1452",
            licence="MIT (mark-hobbs/pypd)", specimen="notched-beam",
            model="gradient-damage", folder="datasets/gregoire2013_beam4",
            licence_file="datasets/gregoire2013_beam4/LICENSE-pypd.txt",
            config="datasets/gregoire2013_beam4/demo.toml",
            files=("datasets/gregoire2013_beam4/load_cmod.csv",)),
    Dataset(name="tinloi-que-wst",
            title="wedge-splitting test (LMC/EPFL), 200 x 200 x 97 mm: splitting force vs opening, one curve",
            citation="Que (2003), PhD thesis, UNSW Sydney (Tin-Loi & Que's identification of cohesive crack "
                     "parameters)",
            licence="MIT (GAMS-dev/gamsworld)",
            specimen="wedge-splitting", model="cohesive-crack", folder="datasets/tinloi_que_wst",
            licence_file="datasets/tinloi_que_wst/LICENSE-gamsworld.txt",
            config="datasets/tinloi_que_wst/config.toml", files=("datasets/tinloi_que_wst/load_opening.csv",)),
)}


def names() -> list[str]:
    """The names of the bundled data sets, in the order of :data:`DATASETS`."""
    return list(DATASETS)


def get(name: str) -> Dataset:
    """The data set called ``name``.

    Raises
    ------
    UnknownDataset
        For a name not in :data:`DATASETS`; the message lists the known names.
    """
    if not isinstance(name, str) or name not in DATASETS:
        raise UnknownDataset(f"unknown data set {name!r}; the data sets are: {', '.join(DATASETS)} "
                             "(`fracid datasets` lists them)")
    return DATASETS[name]


def path(name: str) -> Path:
    """The installed data file of the data set ``name`` (the first one its configuration reads).

    Parameters
    ----------
    name : str
        A name of :data:`DATASETS`.

    Returns
    -------
    Path
        A CSV with a header row; its README gives the columns and their units (mm, N).
    """
    return get(name).file_paths[0]


def load(name: str) -> ExperimentalData:
    """The data set ``name`` as its default configuration reads it: y_exp and C_exp.

    The ``[[experiments]]`` blocks of the configuration are read by :func:`fracid.config.build_data`, that
    is by the builders of :mod:`fracid.data` (``from_envelope``, ``with_std`` ...) with the configuration's
    points, range and scatter rule, so what is loaded here is exactly what ``fracid identify`` fits.

    Parameters
    ----------
    name : str
        A name of :data:`DATASETS`.

    Returns
    -------
    fracid.data.ExperimentalData
        Control values [mm], forces [N], covariance [N^2], the rules applied in ``notes``.
    """
    from fracid.config import build_data, load_config

    return build_data(load_config(get(name).config_path, purpose="identify"))
