"""End to end in headless Chromium: on a two-disc video whose ids swap at frame 10, pick a box with the mouse, swap
it back from frame 12 by keyboard (only frames >= 12 change), undo, assign with the mouse, export, go to a frame and
id on the timeline, delete by keyboard and undo with the mouse; the page shows what the server serves. Then every
correction and undo, each by keyboard and by mouse, and the next doubtful range by key and by its list."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lookalike.proofread import Correction, Doubt, Session
from lookalike.viz.label.proofread import ProofreadApp
from tests.test_label_browser import chromium_page
from tests.test_proofread_page import FRAMES, Served, lane_ids, open_page, two_discs

SCREENSHOT = Path(__file__).resolve().parents[1] / "docs" / "images" / "proofread-page.png"
SCALE = 3
UP, DOWN = 30 * SCALE, 90 * SCALE  # lanes' centre y (px)


def _boxes(page) -> list[list[float]]:
    return page.eval_on_selector_all("#boxes tbody tr", "rs => rs.map(r => [+r.dataset.id, +r.dataset.sx, "
                                                        "+r.dataset.sy])")


def _click_lane(page, y: float) -> int:
    """Click the box whose centre is on the lane ``y`` (px); its id."""
    box = page.locator("#view").bounding_box()
    tid, sx, sy = min(_boxes(page), key=lambda b: abs(b[2] - y))
    page.mouse.click(box["x"] + sx, box["y"] + sy)
    page.wait_for_function(f"document.getElementById('picked').textContent === '{tid}'")
    return int(tid)


def _click_timeline(page, lane: int, frame: int) -> None:
    box = page.locator("#timeline").bounding_box()
    x = 1 + (frame - 1) / (FRAMES - 1) * (box["width"] - 2)
    page.mouse.click(box["x"] + x + 0.5, box["y"] + 12 * lane + 6)


def _wait_version(page, version: int, frame: int) -> None:
    page.wait_for_function(f"document.body.dataset.shown === '{frame}:{version}'")


def _served_rows(served) -> list[list[float]]:
    return served.request("GET", f"/api/tracks?start=1&count={FRAMES}")[1]["rows"]


def test_proofread_page_end_to_end(tmp_path):
    page_app = open_page(tmp_path, scale=SCALE)
    errors: list[str] = []
    with chromium_page(errors, 960, 600) as page:
        with Served(page_app) as served:
            page.goto(served.url)
            _wait_version(page, 0, 1)
            for _ in range(11):
                page.keyboard.press("ArrowRight")
            _wait_version(page, 0, 12)
            before = _served_rows(served)
            assert lane_ids(before, 12) == {UP: 2, DOWN: 1}
            # swap by keyboard: the upper box (2 since frame 10) swaps with 1 from frame 12 on
            assert _click_lane(page, UP) == 2
            page.keyboard.press("s")
            page.keyboard.type("1")
            page.keyboard.press("Enter")
            _wait_version(page, 1, 12)
            after = _served_rows(served)
            assert all(lane_ids(after, f) == lane_ids(before, f) for f in range(1, 12))  # before 12: unchanged
            assert all(lane_ids(after, f) == {UP: 1, DOWN: 2} for f in range(12, FRAMES + 1))
            assert sorted(b[0] for b in _boxes(page)) == [1, 2]
            assert "changed 36 rows, ids 1, 2, frames 12-20" in page.text_content("#message")
            # undo by keyboard
            page.keyboard.press("u")
            _wait_version(page, 2, 12)
            assert _served_rows(served) == before
            # assign by mouse: the lower box (1) is identity 4 from frame 12 on
            assert _click_lane(page, DOWN) == 1
            page.select_option("#kind", "assign")
            page.fill("#other", "4")
            page.click("#apply-btn")
            _wait_version(page, 3, 12)
            assert lane_ids(_served_rows(served), 12) == {UP: 2, DOWN: 4}
            assert lane_ids(_served_rows(served), 11) == {UP: 2, DOWN: 1}
            assert page.eval_on_selector_all("#corrections li", "ls => ls.map(l => l.textContent)") == \
                ["assign 1 4 from 12"]
            page.click("#export-btn")
            page.wait_for_function("document.getElementById('message').textContent.startsWith('wrote')")
            out = np.loadtxt(tmp_path / "two.proofread.txt", delimiter=",")
            assert set(out[out[:, 0] >= 12, 1].astype(int)) == {2, 4}
            if SCREENSHOT.parent.is_dir() and not SCREENSHOT.exists():
                page.screenshot(path=str(SCREENSHOT))
            # the timeline: a click on id 4's lane (lanes 1, 2, 4) at frame 15 goes there and picks 4
            _click_timeline(page, lane=2, frame=15)
            page.wait_for_function("document.body.dataset.frame === '15'")
            assert page.text_content("#picked") == "4"
            page.keyboard.press("Delete")  # delete by keyboard, then undo it
            page.keyboard.press("Enter")
            _wait_version(page, 4, 15)
            assert 4 not in {r[1] for r in _served_rows(served)}
            page.click("#undo-btn")
            _wait_version(page, 5, 15)
            assert lane_ids(_served_rows(served), 15) == {UP: 2, DOWN: 4}
    assert errors == []


def _pick_and_apply(page, lane: float, kind: str, other: str | None = None, by_key: str | None = None) -> int:
    """Click the box on ``lane``, then make the correction ``kind`` (with ``other``) by its key and Enter
    (``by_key``) or by the form's menu and the apply button (mouse); the picked id."""
    tid = _click_lane(page, lane)
    if by_key is not None:
        page.keyboard.press(by_key)
        if other is not None:
            page.keyboard.press("Control+a")  # replace what the field held
            page.keyboard.type(other)
        page.keyboard.press("Enter")
    else:
        page.select_option("#kind", kind)
        if other is not None:
            page.fill("#other", other)
        page.click("#apply-btn")
    return tid


def test_every_correction_by_keyboard_and_by_mouse(tmp_path):
    """Split, merge, swap, assign, delete and undo, each by keyboard and by mouse (ids: 1 on the upper lane and 2 on
    the lower before frame 10, exchanged from 10 on)."""
    page_app = open_page(tmp_path, scale=SCALE)
    errors: list[str] = []
    with chromium_page(errors, 960, 600) as page:
        with Served(page_app) as served:
            page.goto(served.url + "#frame=15")
            _wait_version(page, 0, 15)
            start = _served_rows(served)
            version = 0

            def done(check) -> None:
                nonlocal version
                version += 1
                _wait_version(page, version, 15)
                rows = _served_rows(served)
                assert check(rows), (version, page.text_content("#message"))

            def split(rows) -> bool:  # 1 on the lower lane from 15 on is a new id, 3
                return lane_ids(rows, 15)[DOWN] == lane_ids(rows, 20)[DOWN] == 3 and lane_ids(rows, 14)[DOWN] == 1

            def merged(rows) -> bool:  # 1's rows joined 3
                return 1 not in {r[1] for r in rows} and lane_ids(rows, 12)[DOWN] == lane_ids(rows, 5)[UP] == 3

            for split_key, merge_key in (("x", None), (None, "m")):
                assert _pick_and_apply(page, DOWN, "split", by_key=split_key) == 1
                done(split)
                assert _pick_and_apply(page, DOWN, "merge", "1", by_key=merge_key) == 3
                done(merged)
                page.keyboard.press("u")  # undo by keyboard, then by mouse
                done(split)
                page.click("#undo-btn")
                done(lambda rows: rows == start)
            # swap by mouse from frame 15: frames before it keep their ids
            assert _pick_and_apply(page, UP, "swap", "1") == 2
            done(lambda rows: lane_ids(rows, 15) == {UP: 1, DOWN: 2} and lane_ids(rows, 14) == {UP: 2, DOWN: 1})
            assert _pick_and_apply(page, DOWN, "assign", "5", by_key="a") == 2  # assign by keyboard
            done(lambda rows: lane_ids(rows, 15) == {UP: 1, DOWN: 5} and lane_ids(rows, 14) == {UP: 2, DOWN: 1})
            assert _pick_and_apply(page, DOWN, "delete") == 5  # delete by mouse
            done(lambda rows: 5 not in {r[1] for r in rows} and lane_ids(rows, 15) == {UP: 1})
            assert page.eval_on_selector_all("#corrections li", "ls => ls.map(l => l.textContent)") == \
                ["swap 2 1 from 15", "assign 2 5 from 15", "delete 5"]
    assert errors == []


class _Doubting(Session):
    """A session whose doubtful ranges are given: id 2 in frames 14-16 (most doubtful), id 1 in 4-6."""

    def doubtful(self, threshold: float = 0.5) -> list[Doubt]:
        return [Doubt(2, 14, 16, 1.0), Doubt(1, 4, 6, 0.5)]


def test_next_doubtful_range_by_key_and_by_the_list(tmp_path):
    video, tracks = two_discs(tmp_path, SCALE)
    page_app = ProofreadApp(_Doubting(tracks, frame_rate=10), video, tmp_path / "two.corrections.jsonl",
                            tmp_path / "two.proofread.txt", Correction.from_json)
    errors: list[str] = []
    with chromium_page(errors, 960, 600) as page:
        with Served(page_app) as served:
            page.goto(served.url)
            _wait_version(page, 0, 1)
            assert page.eval_on_selector_all("#doubtful li", "ls => ls.map(l => l.textContent)") == \
                ["id 2: frames 14-16", "id 1: frames 4-6"]
            # N: the next range after the frame shown, then the most doubtful once none is after it
            for frame, picked in ((4, "1"), (14, "2"), (14, "2")):
                page.keyboard.press("n")
                page.wait_for_function(f"document.body.dataset.frame === '{frame}'")
                assert page.text_content("#picked") == picked
            page.click("#doubtful li:nth-child(2)")
            page.wait_for_function("document.body.dataset.frame === '4'")
            assert page.text_content("#picked") == "1"
    assert errors == []
