"""``fracid serve CONFIG [--port N] [--host H]``: the configuration's forward operator served as an UM-Bridge model
(:mod:`fracid.exchange.umbridge_model`), so that samplers and UQ libraries written elsewhere call fracid's models
with their exact sensitivities. Needs the ``umbridge`` extra (``pip install "fracid[umbridge]"``)."""

from __future__ import annotations

import json
from pathlib import Path

from fracid.cli.common import load, out_dir, say, working_in

#: the model's name on the server
MODEL_NAME = "fracid"


def add_parser(sub, parents) -> None:
    """The ``serve`` subcommand's arguments (``parents.stored``: the common options and ``--store``)."""
    p = sub.add_parser("serve", parents=[parents.stored],
                       help="serve the configuration's forward model over UM-Bridge (needs fracid[umbridge])")
    p.add_argument("config", type=Path, help="TOML configuration file (its [identify] parameters are the input)")
    p.add_argument("--port", type=int, default=4242, help="TCP port (default 4242, UM-Bridge's usual)")
    p.add_argument("--host", default="localhost",
                   help="address to listen on (default localhost; 0.0.0.0 for every interface)")
    p.add_argument("--steps", type=int, metavar="N",
                   help="N equal control steps per run instead of the adaptive ones: the output is then a smooth "
                        "function of the parameters and the gradient its exact derivative (for gradient-based "
                        "samplers); default: the configuration's steps, as fracid identify runs them")
    p.set_defaults(run=run_serve)


def _needs_umbridge() -> None:
    from fracid.runtime.exits import UsageError

    try:
        import aiohttp  # noqa: F401 -- the server's; umbridge brings it
        import umbridge  # noqa: F401 -- the clients'; its presence says the extra is installed
    except ImportError as err:
        raise UsageError(f"fracid serve needs the umbridge extra ({err.name} is missing): "
                         'pip install "fracid[umbridge]"') from None


def run_serve(args) -> int:
    """Build the configuration's operator, write OUT/serve.json (what is served), then serve until Ctrl-C."""
    from fracid.config import build_data, build_operator, build_space
    from fracid.exchange.umbridge_model import ServedModel, model_info, with_equal_steps
    from fracid.exchange.umbridge_server import serve
    from fracid.inverse.core.runs import StoredOperator
    from fracid.runtime.exits import UsageError

    _needs_umbridge()
    if not 0 < args.port < 65536:
        raise UsageError(f"--port {args.port}: a TCP port is 1 to 65535")
    if args.steps is not None and args.steps < 2:
        raise UsageError(f"--steps {args.steps}: give at least 2 steps (100 to 300 for a bar or a beam)")
    cfg = load(args, args.config, "identify")
    data = build_data(cfg)
    operator, space = build_operator(cfg, data), build_space(cfg)
    if args.steps is not None:
        operator = with_equal_steps(operator, args.steps)
    out = out_dir(args, cfg)
    with working_in(args, out, store=True) as store:
        plain = StoredOperator(operator, store, study="serve", retry_failed=args.retry_failed)
        exact = plain.differentiated() if operator.differentiable else None
        info = model_info(operator, data, space, Path(cfg.path).resolve())
        (out / "serve.json").write_text(json.dumps(info, indent=1))
        model = ServedModel(MODEL_NAME, plain, exact, info)
        url = f"http://{args.host}:{args.port}"
        try:
            serve([model], args.host, args.port, ready=lambda: say(args, (
                f"serving model {MODEL_NAME!r} at {url} (UM-Bridge protocol 1.0): input {list(operator.names)}, "
                f"output {operator.n_outputs} observations; gradient and Jacobian: "
                f"{'exact' if exact is not None else 'not offered (no exact sensitivities)'}; runs stored in "
                f"{args.store_path}; {out / 'serve.json'} describes it. Ctrl-C stops.")))
        except OSError as err:
            if getattr(err, "errno", None) in (98, 48, 10048, 13):  # in use (Linux, macOS, Windows), no permission
                raise UsageError(f"--port {args.port}: cannot listen at {url} ({err.strerror or err}); choose "
                                 "another port with --port N") from None
            raise
        finally:
            say(args, f"served runs: {plain.computed + (exact.computed if exact else 0)} computed, "
                      f"{plain.reused + (exact.reused if exact else 0)} reused from the run store")
    return 0
