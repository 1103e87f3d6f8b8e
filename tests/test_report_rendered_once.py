"""fracid identify draws each figure once for report.html and figures/ (fracid.report.figures.rendered_once)."""

import base64

from matplotlib.figure import Figure

from _bar_study import write_bar_study
from fracid import cli
from fracid.report import figures


def counting_savefig(monkeypatch):
    calls = []
    savefig = Figure.savefig

    def counted(self, *args, **kwargs):
        calls.append(self)
        return savefig(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", counted)
    return calls


def line_figure(y):
    fig = figures.new_figure(2.0, 1.5)
    fig.add_subplot().plot([0, 1], [0, y])
    return fig


def test_a_stem_is_rendered_once_inside_the_block_only(monkeypatch):
    calls = counting_savefig(monkeypatch)
    with figures.rendered_once():
        first = figures.to_png(line_figure(1.0), stem="fit")
        again = figures.to_png(line_figure(2.0), stem="fit")
        other = figures.to_png(line_figure(1.0), stem="kalman")
        plain = figures.to_png(line_figure(1.0))
    assert again == first and len(calls) == 3
    assert other.startswith(b"\x89PNG") and plain.startswith(b"\x89PNG")
    outside = figures.to_png(line_figure(2.0), stem="fit")
    assert outside != first and len(calls) == 4


def test_identify_writes_the_reports_images_as_files(tmp_path, monkeypatch):
    config = write_bar_study(tmp_path)
    calls = counting_savefig(monkeypatch)
    out = tmp_path / "out"
    assert cli.main(["identify", str(config), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    html = (out / "report.html").read_text()
    files = sorted((out / "figures").glob("*.png"))
    assert {p.stem for p in files} >= {"fit", "kalman", "correlation", "knn_objective", "knn_map"}
    for path in files:
        assert base64.b64encode(path.read_bytes()).decode() in html, path.name
    assert len(calls) == html.count("data:image/png;base64,")  # every image rendered once
