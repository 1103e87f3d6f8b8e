"""A headless Chromium for the tests that render HTML (the reports, the documentation site): the DOM after the
page's scripts ran, and the browser's log. Skips where no browser is installed (.ci/run installs chromium where
apt-get can)."""

import shutil
import subprocess

import pytest


def find_browser():
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    return None


def render(path, tmp_path, query: str = ""):
    """The DOM of ``path`` (with the URL's ``query``, e.g. ``"?q=word"``) after a headless Chromium loaded it
    (its scripts run), and the browser's log; skips without a browser."""
    browser = find_browser()
    if browser is None:
        pytest.skip("no browser (.ci/run installs chromium where apt-get can)")
    command = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               "--enable-logging=stderr", "--v=0", f"--user-data-dir={tmp_path / 'profile'}",
               "--virtual-time-budget=5000", "--dump-dom", path.resolve().as_uri() + query]
    try:
        done = subprocess.run(command, check=False, capture_output=True, text=True, timeout=90)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{browser} did not finish within 90 s")
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout, done.stderr
