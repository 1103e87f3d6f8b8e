"""The demo configuration the benchmarks share, with its mesh's h_fine overridden when asked."""

import dataclasses

from fracid.cli.common import demo_config_path
from fracid.config import load_config


def demo_config(h_fine=None):
    """The bundled demo configuration (Gregoire beam); ``h_fine`` [mm] replaces its mesh size when given."""
    cfg = load_config(demo_config_path(), purpose="identify")
    if h_fine is None:
        return cfg
    options = tuple((k, v) for k, v in cfg.specimen.options if k != "h_fine") + (("h_fine", h_fine),)
    return dataclasses.replace(cfg, specimen=dataclasses.replace(cfg.specimen, options=options))
