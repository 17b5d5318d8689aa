"""``lookalike eval``: score result folders against MOTChallenge ground truth."""

from __future__ import annotations

import csv
import numbers
from pathlib import Path

import typer
from rich import box
from rich.table import Table

from lookalike.cli.app import app, check_names, check_outputs_or_fail, command_line, console, fail, failing, split_list
from lookalike.eval import BENCHMARKS, METRICS
from lookalike.eval.folders import COMBINED, evaluate_folders, folder_results
from lookalike.io.outputs import atomic_path

HEADLINE = {"HOTA": ("HOTA", "DetA", "AssA"), "CLEAR": ("MOTA", "MOTP", "IDSW", "Frag", "CLR_FP", "CLR_FN"),
            "Identity": ("IDF1",)}
SHORT = {"CLR_FP": "FP", "CLR_FN": "FN"}
_METRICS_HELP = f"Any of {', '.join(METRICS)} (comma-separated or repeated; default all)."
PERCENT = {"HOTA", "DetA", "AssA", "LocA", "MOTA", "MOTP", "IDF1", "IDP", "IDR"}


def _cell(key: str, value: float) -> str:
    return f"{100 * value:.2f}" if key in PERCENT else f"{value:g}"


def _columns(metrics: list[str]) -> list[str]:
    return [k for m in ("HOTA", "CLEAR", "Identity") if m in metrics for k in HEADLINE[m]]


@app.command("eval")
def eval_command(
    gt: Path = typer.Option(..., "--gt", help="Ground-truth root: sequence folders with gt/gt.txt (with --points: "
                            "a frame,id,x,y file)."),
    results: list[Path] = typer.Option(..., "--results", help="Folder of <sequence>.txt results (repeat to compare "
                                       "trackers; with --points: result files, scored by box centres)."),
    points: bool = typer.Option(False, "--points", help="Point ground truth (frame,id,x,y): match within --radius."),
    radius: float | None = typer.Option(None, "--radius", min=0.0, help="With --points: match distance in pixels."),
    benchmark: str = typer.Option("MOT15", help=f"Ground-truth rules: {', '.join(BENCHMARKS)}."),
    metrics: list[str] | None = typer.Option(None, "--metrics", help=_METRICS_HELP),
    iou_threshold: float = typer.Option(0.5, help="IoU a CLEAR/identity match needs (boxes)."),
    workers: int = typer.Option(1, help="Processes scoring sequences in parallel."),
    json_path: Path | None = typer.Option(None, "--json", help="Write every value as JSON here."),
    csv_path: Path | None = typer.Option(None, "--csv", help="Write every value as CSV here "
                                             "(one row per tracker and sequence)."),
) -> None:
    """Score trackers with HOTA, CLEAR MOT and identity metrics (values shown in %)."""
    chosen = _chosen(metrics)
    check_outputs_or_fail({"--json": json_path, "--csv": csv_path}, _eval_inputs(gt, results))
    benchmark = next((b for b in BENCHMARKS if b.lower() == benchmark.lower()), benchmark)
    check_names("--benchmark", [benchmark], BENCHMARKS, "benchmark")
    if (points or radius is not None) and (not points or radius is None or radius <= 0):
        fail("--points and --radius PX go together (point ground truth matched within PX pixels)")
    if points and (benchmark != "MOT15" or iou_threshold != 0.5):
        fail("--benchmark and --iou-threshold are for boxes; --points matches within --radius PX")
    names = [p.name or str(p) for p in results]
    if len(set(names)) != len(names):
        names = [str(p) for p in results]
    scores: dict[str, dict[str, dict[str, float]]] = {}
    for name, folder in zip(names, results):
        with failing(FileNotFoundError, ValueError):
            if points:
                from lookalike.cli.eval_points import score_points  # imported when used: a short start-up

                assert radius is not None
                scores[name] = {COMBINED: score_points(gt, folder, radius, chosen)}
            else:
                scores[name] = evaluate_folders(gt, folder, benchmark=benchmark, metrics=chosen,
                                                iou_threshold=iou_threshold, workers=workers)
    columns = _columns(chosen)
    rules = f"points within {radius:g} px" if points else benchmark
    if len(scores) == 1:
        name, per_seq = next(iter(scores.items()))
        table = _table(f"{name} ({rules})", "sequence", columns)
        for seq, values in per_seq.items():
            table.add_row(seq, *[_cell(c, values[c]) for c in columns], style="bold" if seq == COMBINED else None)
    else:
        table = _table(f"trackers, combined over sequences ({rules})", "tracker", columns)
        for name, per_seq in scores.items():
            table.add_row(name, *[_cell(c, per_seq[COMBINED][c]) for c in columns])
    console.print(table)
    if json_path is not None:
        _write_json(json_path, scores, gt, {"benchmark": benchmark, "metrics": chosen,
                                            "iou_threshold": iou_threshold, "points": points, "radius": radius})
    if csv_path is not None:
        try:
            _write_csv(csv_path, scores)
        except OSError as exc:
            fail(f"--csv: cannot write {csv_path}: {exc.strerror or exc}")


def _eval_inputs(gt: Path, results: list[Path]) -> list[Path]:
    """The files ``eval`` reads (ground truth, ``seqinfo.ini``, result files) and the folders holding them."""
    from lookalike.cli.app import sequence_files

    inputs = [gt, *results, *(sequence_files(gt) if gt.is_dir() else [])]
    for folder in results:
        inputs += sorted(folder.glob("*.txt")) if folder.is_dir() else []
    return inputs


def _chosen(metrics: list[str] | None) -> list[str]:
    chosen = [next((m for m in METRICS if m.lower() == x.lower()), x) for x in (split_list(metrics) or METRICS)]
    check_names("--metrics", chosen, METRICS, "metric")
    return chosen


def _write_json(path: Path, scores: dict[str, dict[str, dict[str, float]]], gt: Path,
                options: dict[str, object]) -> None:
    with failing(ValueError, prefix="--json: "):
        doc = folder_results(scores, gt, command_line(), options)
    from lookalike.cli.bench import write_results  # imported when used: a short start-up

    write_results(doc, path)


def _table(title: str, first: str, columns: list[str]) -> Table:
    table = Table(title=title, box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False,
                  padding=(0, 1), collapse_padding=True)
    table.add_column(first, no_wrap=True)
    for c in columns:
        table.add_column(SHORT.get(c, c), justify="right", no_wrap=True)
    return table


def _write_csv(path: Path, scores: dict[str, dict[str, dict[str, float]]]) -> None:
    keys = list(next(iter(next(iter(scores.values())).values())).keys())
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["tracker", "seq", *keys])
        for tracker, per_seq in scores.items():
            for seq, values in per_seq.items():
                writer.writerow([tracker, seq, *[_csv_cell(values.get(k, "")) for k in keys]])


def _csv_cell(value: object) -> str:
    """A CSV cell: an integer as such, any other number (numpy scalars too) as its shortest round-tripping float."""
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    return str(value)
