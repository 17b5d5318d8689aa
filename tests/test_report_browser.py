"""The demo's HTML report in headless Chromium: no console errors, every image loaded, every video plays."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

CHROMIUM = Path("/usr/bin/chromium")


def _browser_or_skip():
    if not CHROMIUM.exists() and shutil.which("chromium") is None:
        pytest.skip("Chromium is not installed (make test installs Debian's chromium where it can)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("the Python package playwright is not installed")
    return sync_playwright, str(CHROMIUM if CHROMIUM.exists() else shutil.which("chromium"))


def test_demo_report_opens_without_errors_and_shows_every_image(tmp_path):
    sync_playwright, executable = _browser_or_skip()
    pytest.importorskip("cv2")
    from typer.testing import CliRunner

    from lookalike.cli import app

    out = tmp_path / "demo-out"
    r = CliRunner().invoke(app, ["demo", "--quick", "-o", str(out)])
    assert r.exit_code == 0, r.output
    errors: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=executable, headless=True, args=[
            "--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
            "--disable-sync", "--no-first-run"])
        try:
            page = browser.new_page()
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto((out / "report.html").as_uri(), wait_until="load")
            widths = page.eval_on_selector_all("img", "imgs => imgs.map(i => i.complete ? i.naturalWidth : 0)")
            tables = page.eval_on_selector_all("table", "ts => ts.length")
            # every video element decodes and plays (H.264): metadata loaded, no media error, time advances
            videos = page.eval_on_selector_all("video", """vs => Promise.all(vs.map(v => new Promise(done => {
                const report = () => done({ready: v.readyState, duration: v.duration, error: v.error && v.error.code,
                                           width: v.videoWidth, time: v.currentTime});
                v.addEventListener('error', report);
                v.addEventListener('timeupdate', () => { if (v.currentTime > 0) report(); });
                v.muted = true;
                v.play().catch(report);
                setTimeout(report, 15000);
            })))""")
        finally:
            browser.close()
    assert errors == []
    assert len(widths) >= 5 and all(w > 0 for w in widths), widths
    assert tables >= 3
    assert len(videos) >= 2, videos
    for v in videos:
        assert v["error"] is None and v["duration"] > 0 and v["width"] > 0 and v["time"] > 0, videos
