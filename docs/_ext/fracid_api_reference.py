"""The API reference's pages, written from the packages' ``__all__`` before each build (one source: a name
added to an ``__all__`` gets its entry, a name removed loses it).

Every package of fracid that declares ``__all__`` gets ``reference/api/<package>.rst``: its docstring's summary
and an autosummary table of its public names, whose pages autosummary writes from their numpydoc docstrings.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from pathlib import Path

#: where the pages go, relative to the documentation's source folder
API_FOLDER = Path("reference") / "api"


def public_packages() -> list:
    """The names of fracid's packages that declare ``__all__``, fracid first."""
    import fracid

    names = ["fracid"]
    for info in pkgutil.walk_packages(fracid.__path__, "fracid."):
        if info.ispkg and "__all__" in vars(importlib.import_module(info.name)):
            names.append(info.name)
    return names


def public_names(package: str) -> list:
    """The names of ``package.__all__``, in its order."""
    return list(importlib.import_module(package).__all__)


def _summary(module) -> str:
    doc = inspect.getdoc(module) or ""
    return " ".join(doc.split("\n\n")[0].split())


def page(package: str) -> str:
    """The reStructuredText of one package's page."""
    module = importlib.import_module(package)
    title = f"``{package}``"
    lines = [title, "=" * len(title), "", f".. currentmodule:: {package}", "", _summary(module), "",
             ".. autosummary::", "   :toctree: ../generated", "   :nosignatures:", ""]
    lines += [f"   {name}" for name in public_names(package)]
    return "\n".join(lines) + "\n"


def index(packages: list) -> str:
    lines = ["Python API", "==========", "",
             "Every public name of fracid and of its packages' ``__all__``, from its numpydoc docstring. Units "
             "throughout: N, mm, MPa (N/mm\\ :sup:`2`); the gradient parameter ``c`` in mm\\ :sup:`2`.", "",
             ".. toctree::", "   :maxdepth: 1", ""]
    return "\n".join(lines + [f"   {p}" for p in packages]) + "\n"


def write_pages(source: Path) -> list:
    """Write the index and one page per public package under ``source / API_FOLDER``; the files written."""
    folder = source / API_FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    packages = public_packages()
    written = [folder / "index.rst"]
    _write(written[0], index(packages))
    for package in packages:
        written.append(folder / f"{package}.rst")
        _write(written[-1], page(package))
    for stale in set(folder.glob("*.rst")) - set(written):
        stale.unlink()
    return written


def _write(path: Path, text: str) -> None:
    # unchanged pages keep their time stamp, so that an incremental build does not read them again
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


def _on_config_inited(app, config) -> None:
    write_pages(Path(app.srcdir))


def setup(app):
    app.connect("config-inited", _on_config_inited)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
