"""``fracid serve``: the configuration's forward operator over UM-Bridge, called by the ``umbridge`` client from
this process while the server runs in a subprocess; evaluate against ``fracid simulate`` and the operator,
apply_jacobian and gradient against the direct differentiation and central differences; errors in the protocol's
form; the runs in the run store."""

import socket
import time
from pathlib import Path

import numpy as np
import pytest

from hostile import FRACID, ENV, TRUTH, bar_config, run_fracid, synthetic_curve, write_csv

umbridge = pytest.importorskip("umbridge")
requests = pytest.importorskip("requests")

X = np.array(TRUTH)  # (c, beta) of the bar's configuration, [mm^2, -]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def start(folder, *options):
    """(url, subprocess) of ``fracid serve`` on the 40-element bar identifying (c, beta), once it answers."""
    import subprocess

    write_csv(folder / "bar.csv", *synthetic_curve())
    (folder / "bar.toml").write_text(bar_config())
    port = free_port()
    proc = subprocess.Popen([*FRACID, "serve", "bar.toml", "--port", str(port), "--workers", "1", *options],
                            cwd=folder, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    url = f"http://localhost:{port}"
    for _ in range(600):
        try:
            if requests.get(f"{url}/Info", timeout=1).ok:
                return url, proc
        except requests.ConnectionError:
            time.sleep(0.1)
        if proc.poll() is not None:
            pytest.fail(f"fracid serve exited: {proc.stderr.read()}")
    proc.terminate()
    pytest.fail("fracid serve did not answer in 60 s")


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    """(url, folder, subprocess) of ``fracid serve`` with the configuration's (adaptive) steps."""
    folder = tmp_path_factory.mktemp("serve")
    url, proc = start(folder)
    try:
        yield url, folder, proc
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def central_differences(model, h):
    """d y / d x of the served evaluate by central differences of relative steps ``h``, column by column."""
    columns = []
    for step in np.eye(2) * h * X:
        columns.append((np.array(model([(X + step).tolist()])[0]) - np.array(model([(X - step).tolist()])[0]))
                       / (2 * step.max()))
    return np.array(columns).T


def operator_of(folder: Path):
    from fracid.config import build_data, build_operator, load_config

    cfg = load_config(folder / "bar.toml", purpose="identify")
    return build_operator(cfg, build_data(cfg))


def test_evaluate_gives_the_operator_and_fracid_simulates_curve(served, tmp_path):
    url, folder, _ = served
    model = umbridge.HTTPModel(url, "fracid")
    assert model.get_input_sizes() == [2] and model.get_output_sizes() == [12]
    y = np.array(model([X.tolist()])[0])
    direct = operator_of(folder)(X)
    assert np.allclose(y, direct.y, rtol=1e-12, atol=0)
    # fracid simulate at the same parameters: its curve at its own steps, interpolated at the data's controls
    write_csv(tmp_path / "bar.csv", *synthetic_curve())
    (tmp_path / "sim.toml").write_text(bar_config(c=str(X[0]), beta=str(X[1])))
    proc = run_fracid(["simulate", "sim.toml", "--out", "sim", "--quiet"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    curve = np.loadtxt(tmp_path / "sim" / "curve.csv", delimiter=",", skiprows=1)
    controls = operator_of(folder).observations[0].controls
    assert np.max(np.abs(np.interp(controls, curve[:, 0], curve[:, 1]) - y)) < 0.01 * y.max()


def test_apply_jacobian_and_gradient_are_the_direct_differentiation(served):
    """Against the direct differentiation in this process, and against central differences of the served evaluate:
    with the adaptive steps, whose jump to damage onset moves with the parameters, the differences also
    differentiate the step positions: measured 3.1 % of the column's largest value at the last points of c's
    column (the same at relative steps 1e-4 to 1e-6), hence 5 %."""
    url, folder, _ = served
    model = umbridge.HTTPModel(url, "fracid")
    S = operator_of(folder).differentiated()(X).S
    columns = np.array([model.apply_jacobian(0, 0, [X.tolist()], list(e)) for e in np.eye(2)]).T
    assert np.allclose(columns, S, rtol=1e-10, atol=1e-14)
    sens = np.linspace(1.0, 2.0, 12)
    assert np.allclose(model.gradient(0, 0, [X.tolist()], sens.tolist()), S.T @ sens, rtol=1e-10)
    error = np.max(np.abs(central_differences(model, 1e-5) - columns), axis=0) / np.max(np.abs(columns), axis=0)
    assert np.all(error < 0.05)


def test_with_equal_steps_the_gradient_is_the_derivative_of_evaluate(tmp_path):
    """``--steps N``: the step sequence no longer moves with the parameters, and central differences of the served
    evaluate agree with apply_jacobian to 1e-8 (measured); 1e-6 asserted."""
    url, proc = start(tmp_path, "--steps", "100")
    try:
        model = umbridge.HTTPModel(url, "fracid")
        columns = np.array([model.apply_jacobian(0, 0, [X.tolist()], list(e)) for e in np.eye(2)]).T
        error = np.max(np.abs(central_differences(model, 1e-5) - columns), axis=0) / np.max(np.abs(columns), axis=0)
        assert np.all(error < 1e-6), error
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def test_model_info_names_units_bounds_and_the_data(served):
    url, folder, _ = served
    info = requests.post(f"{url}/ModelInfo", json={"name": "fracid"}).json()
    assert info["support"] == {"Evaluate": True, "Gradient": True, "ApplyJacobian": True, "ApplyHessian": False}
    inputs = info["fracid"]["inputs"]
    assert [(i["name"], i["unit"], i["lower"], i["upper"]) for i in inputs] == [("c", "mm^2", 0.5, 4.0),
                                                                              ("beta", "-", 100.0, 500.0)]
    assert len(info["fracid"]["data"]) == 12 and info["fracid"]["std"] == [0.02] * 12
    assert (folder / "results" / "serve.json").is_file()


@pytest.mark.parametrize("body, status, kind, words", [
    ({"name": "fracid", "input": [[-1.0, 250.0]], "config": {}}, 400, "InvalidInput", ["'c' = -1.0", "valid range"]),
    ({"name": "fracid", "input": [[2.0]], "config": {}}, 400, "InvalidInput", ["vector of 2"]),
    ({"name": "other", "input": [[2.0, 250.0]]}, 400, "ModelNotFound", ["other", "fracid"]),
], ids=["out-of-range", "wrong-size", "unknown-model"])
def test_bad_requests_get_the_protocols_errors_with_fracids_words(served, body, status, kind, words):
    url, _, proc = served
    response = requests.post(f"{url}/Evaluate", json=body)
    assert response.status_code == status
    error = response.json()["error"]
    assert error["type"] == kind and all(word in error["message"] for word in words)
    assert proc.poll() is None  # the server goes on


def test_a_failed_run_is_an_invalid_output_error_and_the_runs_are_stored(served):
    url, folder, proc = served
    # beta = 1e6: softening so brittle that the bar snaps back under end displacement control: the run fails
    response = requests.post(f"{url}/Evaluate", json={"name": "fracid", "input": [[2.0, 1e6]], "config": {}})
    assert response.status_code == 500
    error = response.json()["error"]
    assert error["type"] == "InvalidOutput" and "forward run" in error["message"] and "failed" in error["message"]
    assert proc.poll() is None
    from fracid.store.runs import RunStore

    with RunStore(folder / "results" / "runs.sqlite", readonly=True) as store:
        assert len(store.keys(study="serve")) >= 3  # the truth, its derivatives' run, the failure


def test_serve_without_a_free_port_or_with_a_bad_one_is_exit_2(served, tmp_path):
    url, folder, _ = served
    port = url.rsplit(":", 1)[1]
    proc = run_fracid(["serve", "bar.toml", "--port", port, "--out", str(tmp_path / "o")], folder)
    assert proc.returncode == 2 and f"--port {port}" in proc.stderr and "Traceback" not in proc.stderr
    proc = run_fracid(["serve", "bar.toml", "--port", "70000", "--out", str(tmp_path / "p")], folder)
    assert proc.returncode == 2 and "1 to 65535" in proc.stderr


def test_the_examples_emcee_sampler_runs_through_the_server(served, tmp_path, monkeypatch):
    """examples/umbridge/sampler.py, a few steps: its likelihood is the served model's, its draws are written."""
    import importlib.util
    import sys

    pytest.importorskip("emcee")
    url, folder, _ = served
    path = Path(__file__).parents[1] / "examples" / "umbridge" / "sampler.py"
    spec = importlib.util.spec_from_file_location("umbridge_sampler", path)
    sampler = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sampler)
    log_probability, info, counts = sampler.served_target(url)
    direct = operator_of(folder)(X).y
    data, std = np.array(info["data"]), np.array(info["std"])
    assert log_probability(X) == pytest.approx(-0.5 * np.sum(((direct - data) / std) ** 2), rel=1e-12)
    assert log_probability(np.array([0.1, 250.0])) == -np.inf and counts["calls"] == 1  # outside the bounds: no run
    out = tmp_path / "draws.csv"
    monkeypatch.setattr(sys, "argv", ["sampler.py", "--url", url, "--walkers", "4", "--steps", "3", "--burn", "1",
                                      "--out", str(out)])
    sampler.main()
    draws = np.loadtxt(out, delimiter=",", skiprows=1)
    assert draws.shape == (8, 2) and np.all((draws[:, 0] > 0.5) & (draws[:, 0] < 4.0))


class _Unsupported:
    """A served model without derivatives whose evaluate fails or succeeds by its input."""

    name = "plain"
    info = {}

    def supports_evaluate(self):
        return True

    def supports_gradient(self):
        return False

    def supports_apply_jacobian(self):
        return False

    def get_input_sizes(self, config=None):
        return [1]

    def get_output_sizes(self, config=None):
        return [1]

    def __call__(self, parameters, config=None):
        from fracid.exchange.umbridge_model import ServedRunError

        if parameters[0][0] < 0:
            raise ServedRunError("the forward run at {'x': -1.0} failed: no convergence")
        return [[2.0 * parameters[0][0]]]


def test_the_protocols_routes_in_process_unsupported_features_and_malformed_requests():
    """The server's answers without a subprocess: Info, a gradient of a model without derivatives
    (UnsupportedFeature), a body that is not JSON (InvalidInput), a failed run (InvalidOutput), an evaluation."""
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    pytest.importorskip("aiohttp")
    from aiohttp.test_utils import TestClient, TestServer

    from fracid.exchange.umbridge_server import application

    async def exchange():
        with ThreadPoolExecutor(1) as executor:
            async with TestClient(TestServer(application([_Unsupported()], executor))) as client:
                answers = [await (await client.get("/Info")).json()]
                for route, body in (("/Gradient", {"name": "plain", "input": [[1.0]], "sens": [1.0], "outWrt": 0,
                                                   "inWrt": 0}),
                                    ("/Evaluate", "not json"),
                                    ("/Evaluate", {"name": "plain", "input": [[-1.0]]}),
                                    ("/Evaluate", {"name": "plain", "input": [[1.5]]})):
                    response = await (client.post(route, json=body) if isinstance(body, dict)
                                      else client.post(route, data=body))
                    answers.append((response.status, await response.json()))
                return answers

    info, gradient, malformed, failed, evaluated = asyncio.run(exchange())
    assert info == {"protocolVersion": 1.0, "models": ["plain"]}
    assert gradient[0] == 400 and gradient[1]["error"]["type"] == "UnsupportedFeature"
    assert malformed[0] == 400 and malformed[1]["error"]["type"] == "InvalidInput"
    assert failed[0] == 500 and failed[1]["error"] == {"type": "InvalidOutput",
                                                       "message": "the forward run at {'x': -1.0} failed: no convergence"}
    assert evaluated == (200, {"output": [[3.0]]})
