"""``fracid export``'s work as a function: an identification's result -> the text of a material input file
(:func:`export_text`), in the format of :data:`~fracid.exchange.formats.EXPORT_FORMATS`."""

from __future__ import annotations

from fracid.exchange.formats import EXPORT_FORMATS, REPRESENTATIONS
from fracid.exchange.identified import read_identified
from fracid.exchange.units import UNIT_SYSTEMS
from fracid.runtime.exits import UsageError


def _choice(value, allowed, option: str):
    if value not in allowed:
        raise UsageError(f"{option} {value}: choose one of {', '.join(allowed)}")
    return allowed[value] if isinstance(allowed, dict) else value


def export_text(result, to: str, units: str = "N-mm-MPa", representation: str | None = None) -> str:
    """The material input of the identification in ``result`` (a ``result.json`` path) for ``to``.

    Parameters
    ----------
    result : path
        ``result.json`` of ``fracid identify`` (or posterior, compare's per-model results).
    to : str
        A format of :data:`~fracid.exchange.formats.EXPORT_FORMATS` (``"csv"``, ``"abaqus"``, ``"diana"``).
    units : str
        A system of :data:`~fracid.exchange.units.UNIT_SYSTEMS`.
    representation : {"discrete", "smeared"}, optional
        The crack as an interface or smeared over a band; default: the model's
        (``crack_representation``: discrete for the cohesive crack, smeared for the others).

    Raises
    ------
    UsageError
        Bad options, a result fracid cannot read, a model with no cohesive law.
    """
    fmt = _choice(to, EXPORT_FORMATS, "--to")
    system = _choice(units, UNIT_SYSTEMS, "--units")
    identified = read_identified(result)
    own = identified.model.crack_representation
    kind = own if representation is None else _choice(representation, REPRESENTATIONS, "--as")
    if kind not in fmt.representations:
        if representation is not None:
            raise UsageError(f"--to {to} --as {kind}: {fmt.name} writes {' or '.join(fmt.representations)} cracks "
                             f"only ({fmt.representations_note})")
        kind = fmt.representations[0]
    try:
        table = identified.model.cohesive_law(identified.params)
    except ValueError as err:
        raise UsageError(f"{result}: {err}") from None
    if table is None:
        raise UsageError(f"{result}: the {identified.model_type} model declares no cohesive law to export")
    text = fmt.write(identified, table, system, kind)
    if kind == own:
        return text
    first, rest = text.split("\n", 1)
    return (f"{first}\n{fmt.comment} representation: {kind}, while the {identified.model_type} model's crack is {own}: "
            f"the same law, spread over the code's crack band\n{rest}")
