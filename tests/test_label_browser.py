"""End to end in headless Chromium: label detections by clicking, step frames with keys, reload
and find the labels, check the saved file; then a human-benchmark session and its score."""

from __future__ import annotations

import json
import shutil
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from lookalike.io.robot_sequences import write_robot_sequence
from lookalike.sim import preset, simulate_robots
from lookalike.viz.label import make_server, open_label_app, score_labels

CHROMIUM = Path("/usr/bin/chromium")
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
        "--disable-sync", "--no-first-run"]
SCREENSHOT = Path(__file__).resolve().parents[1] / "docs" / "images" / "label-page.png"


def _browser_or_skip():
    if not CHROMIUM.exists() and shutil.which("chromium") is None:
        pytest.skip("Chromium is not installed (make test installs Debian's chromium where it can)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("the Python package playwright is not installed")
    return sync_playwright, str(CHROMIUM if CHROMIUM.exists() else shutil.which("chromium"))


@contextmanager
def chromium_page(errors: list[str], width: int, height: int) -> Iterator:
    """A page of headless Chromium (``width`` x ``height``) whose console errors and uncaught exceptions go to
    ``errors``; skips when Chromium or playwright is missing."""
    sync_playwright, executable = _browser_or_skip()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=executable, headless=True, args=ARGS)
        try:
            page = browser.new_page(viewport={"width": width, "height": height})
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            yield page
        finally:
            browser.close()


class _Served:
    def __init__(self, app):
        self.server = make_server(app, port=0)
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}/"

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.server.shutdown()
        self.server.server_close()
        self.thread.join(5)


def _rows(page):
    return page.eval_on_selector_all(
        "#detections tbody tr", "rs => rs.map(r => [+r.dataset.label, +r.dataset.sx, +r.dataset.sy])")


def _click(page, det, button="left"):
    box = page.locator("#view").bounding_box()
    _, sx, sy = _rows(page)[det]
    page.mouse.click(box["x"] + sx, box["y"] + sy, button=button)


def _frame(page):
    return int(page.get_attribute("body", "data-frame"))


def _wait_saved(page):
    page.wait_for_function("document.getElementById('save-status').textContent === 'saved'")


def _frames_with(seq, n):
    return [k for k, c in enumerate(seq.arrays.det_valid.sum(axis=1)) if c >= n]


def _label_last_frame_and_screenshot(page, truth):
    """The README's picture: the last frame (reports received by then) labelled by clicks."""
    page.keyboard.press("End")
    last = len(truth) - 1
    page.wait_for_function(f"document.body.dataset.frame === '{last}'")
    for j, want in enumerate(truth[last]):
        for _ in range(int(want) + 1 if want >= 0 else 1):
            _click(page, j, button="left" if want >= 0 else "right")
    _wait_saved(page)
    page.click("#score-btn")
    page.wait_for_selector("#result-rate")
    page.screenshot(path=str(SCREENSHOT))


def test_label_page_end_to_end(tmp_path):
    seq = simulate_robots(preset("m5n3"), 40, 11)
    path = write_robot_sequence(tmp_path / "m5n3-000011.jsonl", seq)
    k0 = _frames_with(seq, 2)[0]
    errors: list[str] = []
    with chromium_page(errors, 1100, 720) as page:
        with _Served(open_label_app(path)) as served:
            page.goto(served.url)
            page.wait_for_selector("body[data-frame='0']")
            for _ in range(k0):
                page.keyboard.press("ArrowRight")
            page.wait_for_function(f"document.body.dataset.frame === '{k0}'")
            n_rows = int(seq.arrays.det_valid[k0].sum())
            page.wait_for_function(f"document.querySelectorAll('#detections tbody tr').length === {n_rows}")
            assert [r[0] for r in _rows(page)][:2] == [-2, -2]
            _click(page, 0)                   # unset -> robot 1
            _click(page, 0)                   # -> robot 2
            _click(page, 1, button="right")   # unset -> false positive
            _click(page, 1, button="right")   # -> robot 3
            _wait_saved(page)
            assert [r[0] for r in _rows(page)][:2] == [1, 2]
            page.keyboard.press("d")
            page.wait_for_function(f"document.body.dataset.frame === '{k0 + 1}'")
            page.keyboard.press("a")
            page.wait_for_function(f"document.body.dataset.frame === '{k0}'")
            page.reload()
            page.wait_for_function(f"document.body.dataset.frame === '{k0}'")
            assert [r[0] for r in _rows(page)][:2] == [1, 2]
            saved = json.loads(path.with_name("m5n3-000011.labels.json").read_text())
            assert saved["labels"][k0][:2] == [1, 2]
            page.check("#show-truth")
            page.click("#score-btn")
            page.wait_for_selector("#result-rate")
            truth = seq.true_labels()
            expected = score_labels(saved["labels"], truth, 3)["success_rate"]
            assert float(page.get_attribute("#result", "data-rate")) == pytest.approx(expected)
            if SCREENSHOT.parent.is_dir() and not SCREENSHOT.exists():
                _label_last_frame_and_screenshot(page, truth)
        assert errors == []


def test_human_benchmark_session_in_the_browser(tmp_path):
    sync_playwright, executable = _browser_or_skip()
    seq = simulate_robots(preset("m3n2"), 20, 5)
    path = write_robot_sequence(tmp_path / "m3n2-000005.jsonl", seq)
    truth = seq.true_labels()
    k1 = _frames_with(seq, 1)[0]
    errors: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=executable, headless=True, args=ARGS)
        try:
            page = browser.new_page()
            page.on("pageerror", lambda e: errors.append(str(e)))
            with _Served(open_label_app(path, benchmark=True)) as served:
                page.goto(f"{served.url}#frame={k1 + 1}")
                page.wait_for_function(f"document.body.dataset.frame === '{k1}'")
                assert page.is_hidden("#truth-toggle") and page.is_hidden("#score-btn")
                _click(page, 0)  # not started: locked
                assert _rows(page)[0][0] == -2
                page.click("#start-btn")
                page.wait_for_selector("#finish-btn:visible")
                want = int(truth[k1][0])
                clicks = want + 1 if want >= 0 else 1
                for _ in range(clicks):
                    _click(page, 0, button="left" if want >= 0 else "right")
                _wait_saved(page)
                assert _rows(page)[0][0] == want
                page.click("#finish-btn")
                page.wait_for_selector("#result-time")
                rate = float(page.get_attribute("#result", "data-rate"))
            saved = json.loads(path.with_name("m3n2-000005.labels.json").read_text())
            bench = saved["benchmark"]
            assert bench["finished_at"] >= bench["started_at"]
            assert bench["frames_scored"] == k1 + 1
            n = sum(len(t) for t in truth[: k1 + 1])
            assert rate == pytest.approx(1 / n) == pytest.approx(bench["success_rate"])
            assert errors == []
        finally:
            browser.close()
