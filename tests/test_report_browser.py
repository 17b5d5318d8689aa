"""The demo's HTML report in headless Chromium: no console errors, every image loaded, every link resolves, every
video plays, shows its poster (the run's first frame after the warm-up) as its first frame, and has its legend
above it, clear of the player."""

from __future__ import annotations

import shutil
from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest

CHROMIUM = Path("/usr/bin/chromium")

# Per video: the poster and the first frame (t = 0) drawn at the video's size, the share of pixels where they differ
# by more than 60 (of 255) in a channel (H.264 blurs an edge a little; the next frame's new caption, boxes and moves
# give 1-8 %), the first frame's spread (a blank frame has none), the legend's and the player's boxes, and whether
# it plays (time advances, no media error).
_VIDEO_CHECK = """vs => Promise.all(vs.map(v => new Promise(done => {
    const fig = v.closest('figure'), legend = fig && fig.querySelector('.legend');
    const box = e => { const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
    const pixels = src => { const w = v.videoWidth, h = v.videoHeight, c = document.createElement('canvas');
        c.width = w; c.height = h; const g = c.getContext('2d'); g.drawImage(src, 0, 0, w, h);
        return g.getImageData(0, 0, w, h).data; };
    const out = {poster: v.getAttribute('poster') || '', legend: legend ? box(legend) : null, video: box(v),
                 error: null, first: null, diff: null, spread: null, played: false, duration: null, width: 0};
    const finish = () => { out.error = v.error && v.error.code; out.duration = v.duration; out.width = v.videoWidth;
                           done(out); };
    const play = () => {
        v.addEventListener('timeupdate', () => { if (v.currentTime > 0) { out.played = true; finish(); } });
        v.muted = true; v.play().catch(e => { out.error = String(e); finish(); }); };
    const compare = () => {
        const img = new Image();
        img.onload = () => {
            try {
                const a = pixels(img), b = pixels(v); let d = 0, s = 0, m = 0;
                for (let i = 0; i < a.length; i += 4) {
                    let big = false;
                    for (let c = 0; c < 3; c++) {
                        big = big || Math.abs(a[i + c] - b[i + c]) > 60; m += b[i + c]; s += b[i + c] * b[i + c]; }
                    d += big; }
                const n = a.length * 3 / 4;
                out.diff = 100 * d / (a.length / 4); out.spread = Math.sqrt(s / n - (m / n) ** 2);
                out.first = v.currentTime;
            } catch (e) { out.error = String(e); }
            play(); };
        img.onerror = () => { out.error = 'poster does not load'; play(); };
        img.src = out.poster; };
    v.addEventListener('error', finish);
    if (v.readyState >= 2) compare(); else v.addEventListener('loadeddata', compare, {once: true});
    setTimeout(finish, 20000);
})))"""


def _browser_or_skip():
    if not CHROMIUM.exists() and shutil.which("chromium") is None:
        pytest.skip("Chromium is not installed (make test installs Debian's chromium where it can)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("the Python package playwright is not installed")
    return sync_playwright, str(CHROMIUM if CHROMIUM.exists() else shutil.which("chromium"))


def _overlap(a: list[float], b: list[float]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def test_demo_report_plays_every_video_from_its_poster_with_the_legend_clear(tmp_path):
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
            "--disable-sync", "--no-first-run", "--autoplay-policy=no-user-gesture-required"])
        try:
            page = browser.new_page(viewport={"width": 1200, "height": 900})
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto((out / "report.html").as_uri(), wait_until="load")
            widths = page.eval_on_selector_all("img", "imgs => imgs.map(i => i.complete ? i.naturalWidth : 0)")
            tables = page.eval_on_selector_all("table", "ts => ts.length")
            refs = page.eval_on_selector_all("[src], [href]", "es => es.map(e => e.src || e.href)")
            videos = page.eval_on_selector_all("video", _VIDEO_CHECK)
        finally:
            browser.close()
    assert errors == []
    assert len(widths) >= 3 and all(w > 0 for w in widths), widths
    assert tables >= 3
    for ref in refs:  # every link and source resolves: embedded, or a file beside the report
        url = urlparse(ref)
        assert url.scheme in ("data", "file"), ref
        if url.scheme == "file":
            assert Path(unquote(url.path)).is_file(), ref
    assert len(videos) == 2, [{k: v for k, v in s.items() if k != "poster"} for s in videos]
    for v in videos:
        shown = {k: x for k, x in v.items() if k != "poster"}
        assert v["poster"].startswith("data:image/"), shown
        assert v["error"] is None and v["played"] and v["duration"] > 0 and v["width"] > 0, shown
        # the first frame is the poster (H.264 only blurs it a little) and is no blank frame
        assert v["first"] == 0 and v["diff"] < 0.75 and v["spread"] > 20, shown
        # the legend is outside the player, above it
        assert v["legend"] is not None and not _overlap(v["legend"], v["video"]), shown
        assert v["legend"][3] <= v["video"][1], shown
