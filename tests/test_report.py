"""HTML report of an identification: a hand-made result (no forward runs), its figures and tables,
self-containment, and (if a Chromium is installed) that every image decodes in a real browser."""

import base64
import re
import struct
import subprocess
import sys

import numpy as np
import pytest

from _browser import render

from fracid.inverse.methods.knn_kalman import IdentificationResult
from fracid.report import fit_metrics, write_report

figures = pytest.importorskip("fracid.report.figures")  # needs matplotlib
stage_figures = pytest.importorskip("fracid.report.stage_figures")

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
NAMES = ["c", "beta", "kappa_i"]
X = np.array([2.5, 310.0, 1.2e-4])
STD = np.array([0.1, 20.0, 4e-6])
CORR = np.array([[1.0, -0.9, 0.2], [-0.9, 1.0, 0.1], [0.2, 0.1, 1.0]])

# two blocks: 8 forces [N] (residual +-1 N, std 2 N) and 4 FPZ widths [mm]
Y_FORCE = np.array([0.0, 10.0, 20.0, 30.0, 20.0, 10.0, 5.0, 2.0])
FIT_FORCE = Y_FORCE + np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0])
Y_WIDTH = np.array([1.0, 2.0, 3.0, 4.0])
FIT_WIDTH = np.array([1.0, 2.0, 3.0, 6.0])
CONTROL = np.concatenate([np.linspace(0.0, 0.07, 8), np.linspace(0.02, 0.08, 4)])  # [mm]
NOTE_DATA = "y = mean of 3 repeated curves (a.csv; b.csv & c.csv)"
NOTE_EVIL = "method <script>alert('x')</script> & co"


def make_result(n_population=20, failed=(7,)):
    rng = np.random.default_rng(0)
    C = CORR * np.outer(STD, STD)
    lower, upper = np.array([0.5, 100.0, 5e-5]), np.array([5.0, 600.0, 2e-4])
    points = lower + rng.random((n_population, 3)) * (upper - lower)
    f = np.sum(((points - X) / (upper - lower) * 20.0) ** 2, axis=1)
    status, errors = ["ok"] * n_population, [""] * n_population
    for i in failed:
        f[i], status[i], errors[i] = np.inf, "failed", "Newton diverged at step 12 <load>"
    order = np.argsort(f, kind="stable")
    k = 5
    best = points[order[:k]]
    x0, C0 = best.mean(axis=0), np.cov(best.T) + np.diag(((upper - lower) / 10) ** 2)
    history = []
    for iteration in (1, 2):
        for step in (1, 2, 3):
            w = step / 3.0
            x = x0 + (X - x0) * (0.8 + 0.2 * (iteration - 1)) * w
            history.append({"iteration": iteration, "step": step, "observations": [step - 1],
                            "x": x, "C": C0 * (1 - w) + C * w})
    return IdentificationResult(
        names=list(NAMES), x=X.copy(), C=C, y_exp=np.concatenate([Y_FORCE, Y_WIDTH]),
        y_fit=np.concatenate([FIT_FORCE, FIT_WIDTH]), std_exp=np.concatenate([np.full(8, 2.0), np.full(4, 0.5)]),
        blocks=[("global", 0, 8), ("fpz_width", 8, 12)], quantities=["force", "fpz_width"], history=history,
        knn={"points": points, "f": f, "status": status, "errors": errors, "order": order, "k": k, "x0": x0,
             "C0": C0, "method": "sobol", "seed": 0},
        runs={"knn": n_population, "knn_failed": len(failed), "kalman": 43, "kalman_run_equivalents": 21.5,
              "kalman_iterations": 2, "wall_seconds": 3725.0},
        notes=[NOTE_DATA, NOTE_EVIL, "Kalman filter: step by step, 2 global iteration(s), tol 0.01 std"],
        converged=True,
    )


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    result = make_result()
    path = tmp_path_factory.mktemp("report") / "sub" / "report.html"
    written = write_report(path, result, control=CONTROL, title="Beam <4> & co", data_notes=[NOTE_DATA],
                           extra_sections=[("Size effect study", "<p id='extra'>study here</p>")])
    assert written == path and path.is_file()
    return result, path, path.read_text(encoding="utf-8")


def png_size(png: bytes) -> tuple[int, int]:
    assert png[:8] == PNG_SIGNATURE
    assert png[12:16] == b"IHDR"
    return struct.unpack(">II", png[16:24])


def test_report_is_self_contained(report):
    _, _, text = report
    assert text.startswith("<!DOCTYPE html>")
    for forbidden in ("http://", "https://", 'src="file', "<link", "url(", "@import"):
        assert forbidden not in text
    sources = re.findall(r'src="([^"]*)"', text)
    assert sources and all(s.startswith("data:image/png;base64,") for s in sources)
    assert "<script src" not in text


def test_every_image_is_a_png(report):
    _, _, text = report
    images = re.findall(r"<img [^>]*>", text)
    assert len(images) == 5  # correlation, fit, Kalman, KNN objective, KNN map
    for tag in images:
        data = re.search(r'src="data:image/png;base64,([^"]+)"', tag).group(1)
        png = base64.b64decode(data, validate=True)
        width, height = png_size(png)
        assert width >= 300 and height >= 300
        assert len(png) > 10_000  # matplotlib drew something
        assert png.rstrip().endswith(b"IEND\xaeB`\x82")
        assert 'alt="' in tag


def test_parameter_table_and_sections(report):
    result, _, text = report
    table = text[text.index("<h2>Identified parameters</h2>"):text.index("<h2>Correlation</h2>")]
    rows = re.findall(r"<tr>(.*?)</tr>", table)
    cells = [re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", row) for row in rows]
    assert cells[0] == ["parameter", "value", "std", "unit", "std / value [%]"]
    assert cells[1] == ["c", "2.5", "0.1", "mm^2", "4"]
    assert cells[2] == ["beta", "310", "20", "-", "6.45"]
    assert cells[3] == ["kappa_i", "0.00012", "4e-06", "-", "3.33"]
    for heading in ("Correlation", "Fit", "Kalman filter", "KNN population", "Run statistics", "Notes",
                    "Size effect study"):
        assert f"<h2>{heading}</h2>" in text
    assert text.index("<h2>Notes</h2>") < text.index("<h2>Size effect study</h2>")
    assert "<p id='extra'>study here</p>" in text  # fragments are not escaped
    # correlation table, run statistics, ranked population
    assert "<td>-0.900</td>" in text and "<td>+0.200</td>" in text
    assert "3725 s (1 h 2 min 5 s)" in text
    assert "<td>43</td>" in text and "<td>21.5</td>" in text
    ranked = text[text.index("best population points"):text.index("<h2>Run statistics</h2>")]
    assert ranked.count("<tr") == 11  # header and 10 points
    best = int(result.knn["order"][0])
    assert f"<td>{result.knn['f'][best]:.5g}</td>" in ranked


def test_text_is_escaped(report):
    _, _, text = report
    assert "<title>Beam &lt;4&gt; &amp; co</title>" in text and "<h1>Beam &lt;4&gt; &amp; co</h1>" in text
    assert "<script>alert" not in text
    assert "method &lt;script&gt;alert(&#x27;x&#x27;)&lt;/script&gt; &amp; co" in text
    assert "(a.csv; b.csv &amp; c.csv)" in text
    assert text.count(NOTE_DATA.replace("&", "&amp;")) == 1  # listed once, under data rules
    assert text.count("<script>") == 1  # only the image-count script


def test_fit_metrics_hand_computed():
    metrics = fit_metrics(make_result())
    force, width = metrics
    assert force["block"] == "global" and force["n"] == 8
    assert force["rms"] == pytest.approx(1.0)  # residual +-1 N everywhere
    assert force["rms_percent"] == pytest.approx(100.0 / 30.0)
    assert force["peak_measured"] == 30.0 and force["peak_computed"] == 29.0
    assert force["peak_error_percent"] == pytest.approx(-100.0 / 30.0)
    assert force["index_peak_measured"] == force["index_peak_computed"] == 3
    assert force["f"] == pytest.approx(8 * 0.25)
    assert width["block"] == "fpz_width"
    assert width["rms"] == pytest.approx(1.0)  # sqrt((0 + 0 + 0 + 2^2) / 4) mm
    assert width["rms_percent"] == pytest.approx(25.0)
    assert width["peak_computed"] == 6.0 and width["peak_error_percent"] == pytest.approx(50.0)
    assert width["index_peak_computed"] == 11 and width["f"] == pytest.approx(16.0)


def test_fit_metrics_in_report(report):
    _, _, text = report
    section = text[text.index("<h2>Fit</h2>"):text.index("<h2>Kalman filter</h2>")]
    cells = '<td class="text">global</td><td class="text">N</td><td>8</td><td>1</td><td>3.33</td><td>30</td><td>29</td>'
    assert cells + "<td>-3.33</td><td>2</td>" in section
    cells = '<td class="text">fpz_width</td><td class="text">mm</td><td>4</td><td>1</td><td>25</td><td>4</td><td>6</td>'
    assert cells + "<td>50</td><td>16</td>" in section  # f = (2 mm / 0.5 mm)^2


def test_figures_have_labelled_axes():
    result = make_result()
    fig = figures.fit_figure(result, CONTROL)
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_title() for ax in axes] == ["global", "fpz_width"]
    assert [ax.get_xlabel() for ax in axes] == ["control [mm]"] * 2
    assert [ax.get_ylabel() for ax in axes] == ["force [N]", "fpz_width [mm]"]
    fig = stage_figures.history_figure(result)
    assert [ax.get_ylabel() for ax in fig.axes] == ["c [mm^2]", "beta [-]", "kappa_i [-]"]
    assert sum(1 for line in fig.axes[0].lines if line.get_linestyle() == ":") == 1  # one iteration boundary
    fig = stage_figures.population_objective_figure(result)
    assert fig.axes[0].get_yscale() == "log" and fig.axes[0].get_ylabel() == "objective f [-]"
    assert stage_figures.strongest_pair(result) == (0, 1)
    fig = stage_figures.population_map_figure(result)
    assert fig.axes[0].get_xlabel() == "c [mm^2]" and fig.axes[0].get_ylabel() == "beta [-]"
    # the 2-std ellipse: every point at Mahalanobis distance 2 from the estimate
    e = figures.covariance_ellipse(X[:2], result.C[:2, :2])
    d = e - X[:2]
    np.testing.assert_allclose(np.einsum("ni,ij,nj->n", d, np.linalg.inv(result.C[:2, :2]), d), 4.0, rtol=1e-9)
    png = figures.to_png(figures.correlation_figure(result))
    assert png[:8] == PNG_SIGNATURE


def test_minimal_result_from_json_lists(tmp_path):
    """One parameter, JSON-like lists (inf as None), no Kalman history: no map, sections say so."""
    d = make_result().to_dict()
    result = IdentificationResult(
        names=["c"], x=np.array([2.5]), C=np.array([[0.01]]), y_exp=d["y_exp"], y_fit=d["y_fit"],
        std_exp=d["std_exp"], blocks=[],
        knn={"points": [[p[0]] for p in d["knn"]["points"]], "f": d["knn"]["f"], "status": d["knn"]["status"],
             "errors": d["knn"]["errors"], "order": d["knn"]["order"], "k": 3},
        runs={"knn": 20}, notes=[],
    )
    assert None in result.knn["f"]
    assert stage_figures.population_map_figure(result) is None and stage_figures.history_figure(result) is None
    text = write_report(tmp_path / "r.html", result).read_text()
    assert "No history of this stage in this result." in text and "not converged" in text
    assert len(re.findall(r"<img ", text)) == 3  # correlation, fit (index axis), KNN objective
    fig = figures.fit_figure(result)
    assert fig.axes[0].get_xlabel() == "point index in the block [-]"


def test_importing_the_report_package_does_not_import_matplotlib():
    code = "import sys, fracid.report; assert 'matplotlib' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def check_rendered(dom, log, images, cells=()):
    """Every one of ``images`` figures decoded, no console error, and the table ``cells`` in the DOM."""
    body = re.search(r"<body[^>]*>", dom)
    assert body, f"no <body> in the dumped DOM: {dom[:500]!r} {log[-1000:]}"
    loaded = re.search(r'data-images-loaded="(\d+)"', body.group(0))
    total = re.search(r'data-images-total="(\d+)"', body.group(0))
    assert loaded and total, f"the load script did not run: {body.group(0)}"
    assert int(total.group(1)) == images
    assert int(loaded.group(1)) == int(total.group(1))
    console = [line for line in log.splitlines() if "CONSOLE" in line or "Uncaught" in line]
    assert console == []
    text = re.sub(r"<[^>]+>", " ", dom)
    for cell in cells:
        assert re.search(rf"<t[dh][^>]*>\s*{re.escape(cell)}", dom), cell
        assert cell in text


def test_images_load_in_a_browser(report, tmp_path):
    _, path, _ = report
    check_rendered(*render(path, tmp_path), images=5, cells=NAMES)


def test_posterior_page_renders_in_a_browser(tmp_path):
    from fracid.inverse.sampling.posterior_result import PosteriorResult
    from fracid.report.posterior import write_posterior_page

    x = np.random.default_rng(1).normal([2.0, 250.0], [0.1, 10.0], size=(50, 2))
    w = np.full(50, 1 / 50)
    result = PosteriorResult(["c", "beta"], x, w, np.zeros(50), np.zeros((50, 0)), np.zeros(0), np.zeros(0), 50.0, 1,
                             0, np.array([2.0, 250.0]), np.diag([0.01, 100.0]), (x.min(axis=0), x.max(axis=0)),
                             status="converged")
    png = figures.to_png(figures.correlation_figure(make_result()))
    path = write_posterior_page(tmp_path / "posterior.html", result, {"corner": png, "posterior_predictive": png})
    check_rendered(*render(path, tmp_path), images=2, cells=["c", "beta"])


def test_warnings_head_the_report_poor_fit_bound_and_failed_runs(tmp_path):
    from dataclasses import replace

    result = make_result()
    poor = replace(result, y_fit=result.y_exp * 0.5, at_bound=["beta"], status="not converged: 10 global iterations "
                   "reached, the last moved the estimate by 0.3 std", converged=False,
                   runs={**result.runs, "kalman_failed": 2})
    text = "\n".join(poor.warnings())
    assert "fit is poor" in text and f"{poor.rms_percent:.3g} %" in text and "beta = " in text
    assert "not converged" in text and "2 in the Kalman stage" in text and "1 of 20 KNN" in text
    html = write_report(tmp_path / "r.html", poor, control=CONTROL).read_text(encoding="utf-8")
    # poor fit, the elastic slope 50 % softer (through the origin: one point at 5 std), the peak 50 % below the
    # measured one, the bound, not converged, failed runs
    assert html.count('<span class="warn">warning</span>') == 6 and "beta (at a bound)" in html
    assert "the model is 50 % softer than the data in block &#x27;global&#x27;" in html
    assert "the model&#x27;s peak is 50 % below the measured one in block &#x27;global&#x27;" in html
    assert "report.html" not in html  # the warnings do not send the reader to the page they are in
    assert make_result().warnings() == ["failed forward runs: 1 of 20 KNN, 0 in the Kalman stage (each with its "
                                        "reason, in the result)"]
