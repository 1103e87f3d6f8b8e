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


def homes(packages: list) -> dict:
    """(package, name) -> the package whose page documents the object: of the packages exporting the same
    object under that name, the deepest (``fracid.data.dic`` over ``fracid.data``, ``fracid.specimens`` over
    ``fracid``), so that a re-exported object has one entry and the others link to it."""
    exporters = {}
    for package in packages:
        module = importlib.import_module(package)
        for name in public_names(package):
            exporters.setdefault((name, id(getattr(module, name))), []).append(package)
    found = {}
    for (name, _), where in exporters.items():
        home = max(where, key=lambda p: p.count("."))
        found.update({(package, name): home for package in where})
    return found


def page(package: str, home: dict) -> str:
    """The reStructuredText of one package's page: an autosummary table of the names it is the home of, and
    links to the entries of the names it re-exports."""
    module = importlib.import_module(package)
    title = f"``{package}``"
    names = public_names(package)
    own = [name for name in names if home[(package, name)] == package]
    lines = [title, "=" * len(title), "", f".. currentmodule:: {package}", "", _summary(module), ""]
    if own:
        lines += [".. autosummary::", "   :toctree: ../generated", "   :nosignatures:", ""]
        lines += [f"   {name}" for name in own] + [""]
    others = [name for name in names if name not in own]
    if others:
        lines += [f"Also exported by ``{package}`` (documented where they are defined):", ""]
        lines += [f"- ``{package}.{name}``: :py:obj:`{home[(package, name)]}.{name}`" for name in others]
    return "\n".join(lines) + "\n"


def all_modules() -> list:
    """Every module and package of fracid, by name (the internal ones too: the extension seams live there)."""
    import fracid

    return ["fracid"] + sorted(info.name for info in pkgutil.walk_packages(fracid.__path__, "fracid.")
                               if not info.name.endswith("__main__"))


def module_page(name: str) -> str:
    """The reStructuredText of one module's page: its docstring (what it holds, why it is there); the public
    names are documented on their packages' pages."""
    title = f"``{name}``"
    return "\n".join([title, "=" * len(title), "", f".. automodule:: {name}", "   :no-members:"]) + "\n"


def index(packages: list) -> str:
    lines = ["Python API", "==========", "",
             "Every public name of fracid and of its packages' ``__all__``, from its numpydoc docstring. Units "
             "throughout: N, mm, MPa (N/mm\\ :sup:`2`); the gradient parameter ``c`` in mm\\ :sup:`2`.", "",
             ".. toctree::", "   :maxdepth: 1", ""]
    lines += [f"   {p}" for p in packages]
    lines += ["", "Every module", "------------", "",
              "The docstring of every module of fracid: what it holds and why, the extension seams (the registries "
              "of models, specimens, experiment kinds, inverse methods) among them.", "",
              ".. toctree::", "   :maxdepth: 1", ""]
    return "\n".join(lines + [f"   modules/{m}" for m in all_modules()]) + "\n"


def write_pages(source: Path) -> list:
    """Write the index and one page per public package under ``source / API_FOLDER``; the files written."""
    folder = source / API_FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    packages = public_packages()
    written = [folder / "index.rst"]
    _write(written[0], index(packages))
    home = homes(packages)
    for package in packages:
        written.append(folder / f"{package}.rst")
        _write(written[-1], page(package, home))
    (folder / "modules").mkdir(exist_ok=True)
    for name in all_modules():
        written.append(folder / "modules" / f"{name}.rst")
        _write(written[-1], module_page(name))
    for stale in set(folder.glob("**/*.rst")) - set(written):
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
