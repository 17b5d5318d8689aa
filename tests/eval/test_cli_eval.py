"""``lookalike eval`` on tiny folders written in tmp_path."""

from __future__ import annotations

import csv
import json
from pathlib import Path

from typer.testing import CliRunner

from lookalike.cli import app


def _write(tmp_path: Path) -> tuple[Path, Path, Path]:
    gt_root = tmp_path / "gt"
    seq = gt_root / "SEQ-1"
    (seq / "gt").mkdir(parents=True)
    (seq / "seqinfo.ini").write_text("[Sequence]\nname=SEQ-1\nframeRate=10\nseqLength=4\n")
    (seq / "gt" / "gt.txt").write_text("".join(f"{f},1,0,0,10,10,1,1,1\n" for f in range(1, 5)))
    good, bad = tmp_path / "good", tmp_path / "bad"
    good.mkdir()
    bad.mkdir()
    (good / "SEQ-1.txt").write_text("".join(f"{f},3,0,0,10,10,1,-1,-1,-1\n" for f in range(1, 5)))
    # switches id half way: IDSW 1 -> MOTA 0.75
    (bad / "SEQ-1.txt").write_text("".join(f"{f},{3 if f < 3 else 4},0,0,10,10,1,-1,-1,-1\n" for f in range(1, 5)))
    return gt_root, good, bad


def test_eval_writes_json_and_csv_and_compares(tmp_path: Path) -> None:
    gt_root, good, bad = _write(tmp_path)
    runner = CliRunner()
    out = runner.invoke(app, ["eval", "--gt", str(gt_root), "--results", str(good), "--results", str(bad),
                              "--json", str(tmp_path / "r.json"), "--csv", str(tmp_path / "r.csv")])
    assert out.exit_code == 0, out.output
    assert "good" in out.output and "bad" in out.output
    doc = json.loads((tmp_path / "r.json").read_text())
    scores = {(r["tracker"], r["sequence"]): r for r in doc["tables"]["scores"]}
    assert scores["good", "SEQ-1"]["metrics"]["mota"] == 1.0
    combined = scores["bad", None]
    assert combined["combined"] and combined["metrics"]["mota"] == 0.75 and combined["metrics"]["idsw"] == 1
    assert doc["header"]["sequences"] == 1 and doc["header"]["frames"] == 4
    rows = list(csv.DictReader(open(tmp_path / "r.csv")))
    assert [(r["tracker"], r["seq"]) for r in rows] == [
        ("good", "SEQ-1"), ("good", "COMBINED"), ("bad", "SEQ-1"), ("bad", "COMBINED")]


def test_eval_missing_sequence_is_an_error(tmp_path: Path) -> None:
    gt_root, good, _ = _write(tmp_path)
    (good / "SEQ-1.txt").unlink()
    out = CliRunner().invoke(app, ["eval", "--gt", str(gt_root), "--results", str(good)])
    assert out.exit_code != 0
    assert "SEQ-1" in out.output
