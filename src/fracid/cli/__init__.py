"""The ``fracid`` command: one module per command; :mod:`~fracid.cli.dispatch` holds the parser and the
dispatch, :mod:`~fracid.cli.common` the plumbing every command shares.

May import every other package of fracid; nothing imports it but ``fracid.__main__``.
"""

from fracid.cli.common import demo_config_path
from fracid.cli.dispatch import main

__all__ = ["demo_config_path", "main"]
