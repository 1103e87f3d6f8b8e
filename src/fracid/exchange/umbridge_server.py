"""The UM-Bridge protocol (version 1.0) over HTTP for fracid's models (:func:`serve`, :func:`application`).

``umbridge.serve_models`` serves any ``umbridge.Model``, but an exception in a model becomes an HTML error page
that no client can read, and its ``ModelInfo`` cannot say more than the support flags. fracid's forward runs can
fail (a run that does not converge), and a client needs the parameters' names, units and bounds; so this module
answers the same routes with aiohttp (a dependency of ``umbridge``): ``Info``, ``ModelInfo`` (the support flags,
plus a ``fracid`` entry, :func:`~fracid.exchange.umbridge_model.model_info`), ``InputSizes``, ``OutputSizes``,
``Evaluate``, ``Gradient``, ``ApplyJacobian``, and returns every failure as the protocol's error object
``{"error": {"type", "message"}}``: ``InvalidInput`` (400) for parameters the model cannot run, ``InvalidOutput``
(500) for a forward run that failed, ``ModelNotFound`` and ``UnsupportedFeature`` (400) as the protocol says.
The forward runs go one at a time through one worker thread, so requests queue rather than compete for the
cores the runs use.
"""

from __future__ import annotations

import asyncio
import json
from concurrent.futures import ThreadPoolExecutor

from fracid.exchange.umbridge_model import ServedInputError, ServedRunError

#: the UM-Bridge protocol version served
PROTOCOL_VERSION = 1.0


def _error(kind: str, message: str, status: int):
    from aiohttp import web

    return web.json_response({"error": {"type": kind, "message": message}}, status=status)


def _output(value):
    from aiohttp import web

    return web.Response(text=json.dumps({"output": value}), content_type="application/json")


def application(models, executor: ThreadPoolExecutor):
    """The aiohttp application answering the UM-Bridge routes for ``models`` (:class:`ServedModel`), their runs
    in ``executor``."""
    from aiohttp import web

    by_name = {model.name: model for model in models}
    routes = web.RouteTableDef()

    async def request_model(request, feature=None):
        try:
            body = await request.json()
        except (json.JSONDecodeError, UnicodeDecodeError):
            return None, None, _error("InvalidInput", "the request body is not JSON", 400)
        model = by_name.get(body.get("name")) if isinstance(body, dict) else None
        if model is None:
            return None, None, _error("ModelNotFound", f"model {body.get('name') if isinstance(body, dict) else body!r}"
                                                       f" not found; served: {sorted(by_name)}", 400)
        if feature is not None and not getattr(model, f"supports_{feature}")():
            return None, None, _error("UnsupportedFeature", f"{feature} is not supported by model {model.name!r} "
                                                            "(its runs have no exact sensitivities)", 400)
        return body, model, None

    async def run(call, *args):
        try:
            return _output(await asyncio.get_running_loop().run_in_executor(executor, call, *args))
        except ServedInputError as err:
            return _error("InvalidInput", str(err), 400)
        except ServedRunError as err:
            return _error("InvalidOutput", str(err), 500)

    @routes.get("/Info")
    async def info(request):
        return web.json_response({"protocolVersion": PROTOCOL_VERSION, "models": sorted(by_name)})

    @routes.post("/ModelInfo")
    async def model_info(request):
        body, model, failed = await request_model(request)
        if failed:
            return failed
        support = {"Evaluate": model.supports_evaluate(), "Gradient": model.supports_gradient(),
                   "ApplyJacobian": model.supports_apply_jacobian(), "ApplyHessian": False}
        return web.json_response({"support": support, "fracid": model.info})

    @routes.post("/InputSizes")
    async def input_sizes(request):
        body, model, failed = await request_model(request)
        return failed or web.json_response({"inputSizes": model.get_input_sizes()})

    @routes.post("/OutputSizes")
    async def output_sizes(request):
        body, model, failed = await request_model(request)
        return failed or web.json_response({"outputSizes": model.get_output_sizes()})

    @routes.post("/Evaluate")
    async def evaluate(request):
        body, model, failed = await request_model(request, "evaluate")
        return failed or await run(model, body.get("input"))

    @routes.post("/Gradient")
    async def gradient(request):
        body, model, failed = await request_model(request, "gradient")
        return failed or await run(model.gradient, body.get("outWrt"), body.get("inWrt"), body.get("input"),
                                   body.get("sens"))

    @routes.post("/ApplyJacobian")
    async def apply_jacobian(request):
        body, model, failed = await request_model(request, "apply_jacobian")
        return failed or await run(model.apply_jacobian, body.get("outWrt"), body.get("inWrt"), body.get("input"),
                                   body.get("vec"))

    app = web.Application(client_max_size=1 << 30)  # a gradient's sens has one entry per observation
    app.add_routes(routes)
    return app


async def _serve_forever(models, host: str, port: int, ready) -> None:
    from aiohttp import web

    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="fracid-serve") as executor:
        runner = web.AppRunner(application(models, executor), access_log=None)
        await runner.setup()
        try:
            await web.TCPSite(runner, host, port).start()
            ready()
            while True:
                await asyncio.sleep(3600)
        finally:
            await runner.cleanup()


def serve(models, host: str = "localhost", port: int = 4242, ready=lambda: None) -> None:
    """Serve ``models`` until interrupted (KeyboardInterrupt propagates); ``ready()`` is called once the port
    listens. OSError when the port cannot be bound (in use, no permission)."""
    asyncio.run(_serve_forever(models, host, port, ready))
