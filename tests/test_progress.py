"""Progress lines when stderr is not a terminal (a log file, a pipe): a line per stage start, then every
FRACID_PROGRESS_SECONDS (30 s by default) and at the end; none with --quiet."""

import re

import pytest

from fracid.runtime import progress
from hostile import bar_config, run_fracid, synthetic_curve, write_csv


def test_lines_at_start_and_end_only_within_a_long_interval(capsys, monkeypatch):
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "3600")
    with progress.progress_lines(), progress.progress_bar(5, "Kalman filter", unit="step") as bar:
        for _ in range(5):
            bar.update(1)
            bar.set_postfix_str("x = 1.5")
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 2 and lines[0] == "fracid: Kalman filter: started, 5 steps"
    assert re.fullmatch(r"fracid: Kalman filter: done, 5/5 steps, 0:\d\d elapsed; x = 1.5", lines[1])


def test_every_update_with_a_zero_interval_and_failed_runs(capsys, monkeypatch):
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "0")
    failed = [0]
    with progress.progress_lines():
        report = progress.batch_lines("forward runs", failed=lambda: failed[0])
        for done in range(4):
            failed[0] = done // 2
            report(done, 3)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0] == "fracid: forward runs: started, 3 runs"
    assert re.match(r"fracid: forward runs: 2/3 runs, 1 failed, 0:\d\d elapsed, ~0:\d\d left", lines[3])
    assert lines[-1].startswith("fracid: forward runs: done, 3/3 runs, 1 failed")


def test_no_lines_unless_asked_for_or_on_a_terminal(monkeypatch):
    assert not progress.lines_wanted(None)  # outside progress_lines: a library call stays silent
    with progress.progress_lines():
        assert progress.lines_wanted(None) and not progress.lines_wanted(False)
        monkeypatch.setattr(progress, "is_terminal", lambda: True)
        assert not progress.lines_wanted(None)  # a terminal has its bars
    with progress.progress_lines(False):
        assert not progress.lines_wanted(None)


def test_a_bad_interval_is_the_default(monkeypatch):
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "soon")
    assert progress.line_interval() == progress.DEFAULT_INTERVAL
    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "2.5")
    assert progress.line_interval() == 2.5


@pytest.mark.slow
def test_identify_prints_progress_lines_into_a_pipe(tmp_path):
    write_csv(tmp_path / "bar.csv", *synthetic_curve())
    (tmp_path / "cfg.toml").write_text(bar_config(), encoding="utf-8")
    proc = run_fracid(["identify", "cfg.toml", "--workers", "1"], tmp_path, env={progress.INTERVAL_VARIABLE: "0"})
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.splitlines()
    assert "fracid: forward runs: started, 8 runs" in lines
    assert any(re.match(r"fracid: forward runs: 3/8 runs, 0 failed, \d+:\d\d elapsed", line) for line in lines)
    assert any(line.startswith("fracid: forward runs: done, 8/8 runs, 0 failed") for line in lines)
    assert "fracid: Kalman filter: started, 4 steps" in lines
    assert any(re.search(r"Kalman filter: \d+/\d+ steps, .*; (start 1/\d, )?iteration 1, x = [\d.]+, [\d.]+$", line) for line in lines)
    quiet = run_fracid(["identify", "cfg.toml", "--workers", "1", "--quiet", "--out", "again"], tmp_path,
                       env={progress.INTERVAL_VARIABLE: "0"})
    assert quiet.returncode == 0 and "fracid: forward runs" not in quiet.stderr


def test_stage_lines_beat_for_the_jobs_still_running(monkeypatch):
    """fracid compare's models side by side: a line per model still running every interval, its last stage in it;
    none for a model done or failed, none at all after the block."""
    import time

    monkeypatch.setenv(progress.INTERVAL_VARIABLE, "0.05")
    written = []
    with progress.StageLines(["a", "b", "c"], written.append) as stages:
        stages.log("a: identifying x, y")
        stages.log("b: failed (ArithmeticError: no run)")
        stages.log("unrelated line")
        time.sleep(0.3)
        stages.log("a: done: x = 1")
        assert stages.status()[0].startswith("c: 0:00 elapsed, waiting for a worker")
        time.sleep(0.15)
    count = len(written)
    time.sleep(0.15)
    assert len(written) == count  # the thread has stopped
    beats_a = [w for w in written if re.fullmatch(r"a: 0:00 elapsed, identifying x, y", w)]
    assert len(beats_a) >= 2 and not any(re.match(r"b: 0:\d\d elapsed", w) for w in written)
    assert "unrelated line" in written and "a: done: x = 1" in written
    last_a = max(i for i, w in enumerate(written) if w.startswith("a: 0:"))
    assert last_a < written.index("a: done: x = 1")  # no beat of a after its end
    assert sum(w.startswith("c: 0:00 elapsed, waiting") for w in written) >= 3
