"""The output rule over every command that writes files: no combination of output paths, drawn from the command's
inputs, links to them, an input folder, each other, an existing folder and fresh paths, ever modifies a file that
was there before the run (other than one given as an output that is not an input), and a refused combination is one
error line (exit 2). The commands and their output options are read from the typer app, so a new output option
without a row here fails :func:`test_every_output_option_is_covered`."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import typer
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from lookalike.cli import app

runner = CliRunner()

OUTPUT_OPTIONS = {"-o", "--json", "--csv", "--png", "--plots", "--gif", "--annotate", "--study", "--port-file",
                  "--rerun-save", "--log"}
"""Option names that name a file or folder a command writes (and ``label --results``, the benchmark result's folder)."""

DET_ROW = "{f},-1,{x},20,20,20,0.9,-1,-1,-1\n"
GT_ROW = "{f},1,{x},20,20,20,1,1,1\n"


@dataclass
class Spec:
    """A command with cheap arguments: ``argv(u, outputs)`` its command line for the universe of inputs ``u`` (name to
    path) and the output option values; ``inputs`` the names in ``u`` it reads (files, or folders read whole);
    ``folders`` its options whose value is a folder; ``cheap`` whether a run with every output fresh is quick
    (others are run only with at least one bad output, which must be refused before any work)."""

    argv: Callable[[dict[str, Path], dict[str, str]], list[str]]
    outputs: tuple[str, ...]
    inputs: tuple[str, ...] = ()
    folders: tuple[str, ...] = ()
    cheap: bool = False
    extra: dict[str, str] = field(default_factory=dict)


def _s(u: dict[str, Path], name: str) -> str:
    return str(u[name])


SPECS: dict[str, Spec] = {
    "track": Spec(lambda u, o: ["track", "--video", _s(u, "video"), "--detections", _s(u, "video_det"),
                                "-o", o["-o"], "--annotate", o["--annotate"]],
                  ("-o", "--annotate"), ("video", "video_det"), cheap=True),
    "eval": Spec(lambda u, o: ["eval", "--gt", _s(u, "gt"), "--results", _s(u, "res"), "--metrics", "CLEAR",
                               "--json", o["--json"], "--csv", o["--csv"]],
                 ("--json", "--csv"), ("gt", "res"), cheap=True),
    "report": Spec(lambda u, o: ["report", _s(u, "json_in"), "-o", o["-o"]], ("-o",), ("json_in",), cheap=True),
    "tune": Spec(lambda u, o: ["tune", _s(u, "gt_seq"), "-t", "sort", "--trials", "1", "-o", o["-o"],
                               "--study", f"sqlite:///{o['--study']}"], ("-o", "--study"), ("gt_seq",)),
    "simulate": Spec(lambda u, o: ["simulate", "--preset", "m3n2", "--frames", "5", "-o", o["-o"]], ("-o",),
                     folders=("-o",), cheap=True),
    "render": Spec(lambda u, o: ["render", "--tracks", _s(u, "video_det"), "--video", _s(u, "video"), "-o", o["-o"],
                                 "--gif", o["--gif"]], ("-o", "--gif"), ("video_det", "video"), cheap=True),
    "render-robots": Spec(lambda u, o: ["render-robots", _s(u, "robots"), "-o", o["-o"]], ("-o",), ("robots",)),
    "record-pixels": Spec(lambda u, o: ["record-pixels", "--preset", "m3n2", "--frames", "5", "--detector-model",
                                        _s(u, "model"), "--heading-model", _s(u, "model2"), "-o", o["-o"]],
                          ("-o",), ("model", "model2"), folders=("-o",)),
    "train": Spec(lambda u, o: ["train", "--preset", "m3n2", "--steps", "1", "--recordings", _s(u, "robots_dir"),
                                "--init-from", _s(u, "model"), "-o", o["-o"]],
                  ("-o",), ("robots_dir", "model"), folders=("-o",)),
    "train --search": Spec(lambda u, o: ["train", "--preset", "m3n2", "--steps", "1", "--search", "1", "-o", o["-o"],
                                         "--study", f"sqlite:///{o['--study']}"], ("-o", "--study"), folders=("-o",)),
    "train-appearance": Spec(lambda u, o: ["train-appearance", "--frames", "10", "--epochs", "1", "-o", o["-o"]],
                             ("-o",), folders=("-o",)),
    "train-detector": Spec(lambda u, o: ["train-detector", "--data", _s(u, "frames"), "--stages", "1", "-o", o["-o"]],
                           ("-o",), ("frames",)),
    "train-heading": Spec(lambda u, o: ["train-heading", "--frames", "5", "--test-frames", "5", "-o", o["-o"]],
                          ("-o",)),
    "demo": Spec(lambda u, o: ["demo", "--quick", "-o", o["-o"], "--rerun-save", o["--rerun-save"]],
                 ("-o", "--rerun-save"), folders=("-o",)),
    "serve": Spec(lambda u, o: ["serve", "--duration", "0.1", "--port-file", o["--port-file"]], ("--port-file",)),
    "label": Spec(lambda u, o: ["label", _s(u, "robots"), "--benchmark", "--export", "--results", o["--results"]],
                  ("--results",), ("robots",), folders=("--results",)),
    "bench ident": Spec(lambda u, o: ["bench", "ident", "--frames", "10", "--sequences", "1", "--weights",
                                      _s(u, "weights"), "--json", o["--json"], "--csv", o["--csv"]],
                        ("--json", "--csv"), ("weights",)),
    "bench ident --recordings": Spec(lambda u, o: ["bench", "ident", "--recordings", _s(u, "robots_dir"), "--human",
                                                   _s(u, "robots_dir"), "--json", o["--json"], "--csv", o["--csv"]],
                                     ("--json", "--csv"), ("robots_dir",)),
    "bench divers": Spec(lambda u, o: ["bench", "divers", "--frames", "10", "--png", o["--png"], "--json",
                                       o["--json"], "--csv", o["--csv"]], ("--png", "--json", "--csv")),
    "bench shuffle": Spec(lambda u, o: ["bench", "shuffle", "--frames", "10", "--json", o["--json"], "--csv",
                                        o["--csv"]], ("--json", "--csv")),
    "bench recovery": Spec(lambda u, o: ["bench", "recovery", "--frames", "300", "--json", o["--json"], "--csv",
                                         o["--csv"]], ("--json", "--csv")),
    "bench pixels": Spec(lambda u, o: ["bench", "pixels", "--frames", "5", "--detector-model", _s(u, "model"),
                                       "--heading-model", _s(u, "model2"), "--weights", _s(u, "weights"),
                                       "--json", o["--json"], "--csv", o["--csv"]],
                         ("--json", "--csv"), ("model", "model2", "weights")),
    "bench real": Spec(lambda u, o: ["bench", "real", "--data", _s(u, "gt"), "--params", _s(u, "json_in"),
                                     "--json", o["--json"], "--csv", o["--csv"], "--plots", o["--plots"]],
                       ("--json", "--csv", "--plots"), ("gt", "json_in"), folders=("--plots",)),
    "proofread": Spec(lambda u, o: ["proofread", "--video", _s(u, "video"), "--tracks", _s(u, "res_seq"), "--export",
                                    "-o", o["-o"], "--log", o["--log"]],
                      ("-o", "--log"), ("video", "res_seq"), cheap=True),
}


def _commands():
    """(command words, click command) of every command of the app, groups walked."""
    def walk(command, words):
        if hasattr(command, "commands"):
            for name, sub in command.commands.items():
                yield from walk(sub, [*words, name])
        else:
            yield " ".join(words), command
    yield from walk(typer.main.get_command(app), [])


def test_every_output_option_is_covered():
    found = set()
    for name, command in _commands():
        for param in command.params:
            opts = set(param.opts)
            if opts & OUTPUT_OPTIONS or (name == "label" and "--results" in opts):
                found.add((name, next(o for o in param.opts if o.startswith("--") or o == "-o")
                           if "-o" not in opts else "-o"))
    covered = {(name.split(" --")[0], option) for name, spec in SPECS.items() for option in spec.outputs}
    assert found == covered


def _universe(root: Path) -> dict[str, Path]:
    """Small inputs of every kind a command reads, under ``root``."""
    import numpy as np

    from lookalike.viz.video import VideoWriter

    gt_seq = root / "gt" / "S1"
    (gt_seq / "gt").mkdir(parents=True)
    (gt_seq / "det").mkdir()
    (gt_seq / "seqinfo.ini").write_text("[Sequence]\nname=S1\nframeRate=30\nseqLength=21\n")
    (gt_seq / "gt" / "gt.txt").write_text("".join(GT_ROW.format(f=f, x=10 + f) for f in range(1, 22)))
    (gt_seq / "det" / "det.txt").write_text("".join(DET_ROW.format(f=f, x=10 + f) for f in range(1, 22)))
    (root / "res").mkdir()
    (root / "res" / "S1.txt").write_text("".join(DET_ROW.format(f=f, x=10 + f).replace(",-1,", ",1,", 1)
                                                 for f in range(1, 22)))
    frames = root / "frames"
    frames.mkdir()
    with VideoWriter(root / "in.mp4", fps=10) as writer:
        for k in range(8):
            image = np.zeros((64, 96, 3), np.uint8)
            image[20:40, 10 + 4 * k:30 + 4 * k] = 255
            writer.write(image)
    (root / "in.txt").write_text("".join(DET_ROW.format(f=k + 1, x=10 + 4 * k) for k in range(8)))
    (frames / "000001.png").write_bytes(b"not an image")
    robots_dir = root / "robots"
    assert runner.invoke(app, ["simulate", "--preset", "m3n2", "--frames", "12", "-o", str(robots_dir)]).exit_code == 0
    json_in = root / "in.json"
    r = runner.invoke(app, ["eval", "--gt", str(root / "gt"), "--results", str(root / "res"), "--metrics", "CLEAR",
                            "--json", str(json_in)])
    assert r.exit_code == 0, r.output
    model = Path(__file__).resolve().parents[1] / "src" / "lookalike" / "vision" / "models_data" / "diver_reid.onnx"
    shutil.copy(model, root / "model.onnx")
    (root / "model2.npz").write_bytes(b"model bytes")
    (root / "weights.pt").write_bytes(b"weights bytes")
    return _names(root)


def _names(root: Path) -> dict[str, Path]:
    return {"gt": root / "gt", "gt_seq": root / "gt" / "S1", "res": root / "res", "res_seq": root / "res" / "S1.txt",
            "video": root / "in.mp4",
            "video_det": root / "in.txt", "frames": root / "frames", "robots_dir": root / "robots",
            "robots": next((root / "robots").glob("*.jsonl")), "json_in": root / "in.json",
            "model": root / "model.onnx", "model2": root / "model2.npz", "weights": root / "weights.pt"}


def _files(paths) -> list[Path]:
    return [p for root in paths for p in ([root] if root.is_file() else sorted(root.rglob("*"))) if p.is_file()]


def _state(root: Path) -> dict[Path, tuple[bytes, int]]:
    """Bytes and modification time (ns) of every file under ``root`` (links not followed)."""
    return {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in sorted(root.rglob("*"))
            if p.is_file() and not p.is_symlink()}


_TARGET = st.one_of(st.tuples(st.just("input"), st.integers(0, 50)), st.tuples(st.just("symlink"), st.integers(0, 50)),
                    st.tuples(st.just("hardlink"), st.integers(0, 50)), st.tuples(st.just("input_folder"),
                                                                                    st.integers(0, 50)),
                    st.tuples(st.just("fresh"), st.integers(0, 2)), st.tuples(st.just("folder"), st.just(0)),
                    st.tuples(st.just("file"), st.just(0)))


@pytest.fixture(scope="module")
def template(tmp_path_factory):
    base = tmp_path_factory.mktemp("universe")
    (base / "u").mkdir()
    _universe(base / "u")
    return base


@pytest.mark.parametrize("name", list(SPECS))
@settings(max_examples=8, deadline=None, suppress_health_check=[
    HealthCheck.function_scoped_fixture, HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(data=st.data())
def test_no_combination_of_output_paths_modifies_an_input(template, tmp_path, name, data):
    spec = SPECS[name]
    root = Path(tempfile.mkdtemp(dir=tmp_path))
    shutil.copytree(template, root, dirs_exist_ok=True, copy_function=shutil.copy2)
    u = _names(root / "u")
    inputs = [u[n] for n in spec.inputs]
    input_files = _files(inputs)
    input_folders = [p for p in inputs if p.is_dir()] + [p.parent for p in input_files]
    (root / "existing_folder").mkdir()
    (root / "existing_file").write_text("an earlier output\n")
    outputs: dict[str, Path] = {}
    bad = False
    for k, option in enumerate(spec.outputs):
        kind, i = data.draw(_TARGET, label=option)
        if kind in ("input", "symlink", "hardlink") and input_files:
            src = input_files[i % len(input_files)]
            path = src if kind == "input" else root / f"{kind}{k}{src.suffix}"
            if kind == "symlink":
                path.symlink_to(src)
            elif kind == "hardlink":
                os.link(src, path)
            bad = True
        elif kind == "input_folder" and input_folders:
            path, bad = input_folders[i % len(input_folders)], bad or option not in spec.folders
        elif kind == "folder":
            path, bad = root / "existing_folder", bad or option not in spec.folders
        elif kind == "file":  # an earlier output, say: replaced by a file output, refused as a folder output
            path, bad = root / "existing_file", bad or option in spec.folders
        else:  # a fresh path, possibly shared with another output
            path = root / "fresh" / f"out{i}"
            bad = bad or any(p == path for p in outputs.values())
        outputs[option] = path
    assume(bad or spec.cheap)
    before = _state(root)
    written = {p for p in before if any(p == o or (o.exists() and os.path.samefile(p, o)) for o in outputs.values())}
    r = runner.invoke(app, spec.argv(u, {o: str(p) for o, p in outputs.items()}))
    assert "Traceback" not in r.output, r.output
    after = _state(root)
    protected = set(_files(inputs)) | (set(before) - written)
    for p in protected:
        assert after.get(p) == before[p], (name, p, outputs, r.output)
    if r.exit_code != 0:  # one error line, the last (a warning about the input may come before it)
        assert r.exit_code == 2, r.output
        lines = [line for line in r.output.splitlines() if line.strip()]
        assert lines[-1].startswith("error:") and sum(line.startswith("error:") for line in lines) == 1, r.output


def test_render_robots_onto_a_link_to_its_sequence_is_refused(tmp_path):
    """It used to write the video through the link, replacing the sequence."""
    assert runner.invoke(app, ["simulate", "--preset", "m3n2", "--frames", "5", "-o", str(tmp_path)]).exit_code == 0
    sequence = next(tmp_path.glob("*.jsonl"))
    before = sequence.read_bytes()
    (tmp_path / "video.mp4").symlink_to(sequence)
    r = runner.invoke(app, ["render-robots", str(sequence), "-o", str(tmp_path / "video.mp4")])
    assert r.exit_code == 2 and r.output.startswith("error:") and "is the input" in r.output, r.output
    assert sequence.read_bytes() == before


def test_train_search_study_that_is_not_a_database_is_one_line(tmp_path):
    """It used to end in an SQLAlchemy traceback after the output folder was made."""
    other = tmp_path / "notes.txt"
    other.write_text("not a database\n")
    r = runner.invoke(app, ["train", "--preset", "m3n2", "--steps", "1", "--search", "1", "-o", str(tmp_path / "run"),
                            "--study", f"sqlite:///{other}"])
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert r.exit_code == 2 and len(lines) == 1 and "--study" in lines[0] and "not a database" in lines[0], r.output
    assert other.read_text() == "not a database\n"


def test_video_and_gif_outputs_without_a_known_suffix_are_written(template, tmp_path):
    """An MP4 and a GIF, whatever their names (they were refused after the rendering, naming a temporary file)."""
    u = _names(template / "u")
    r = runner.invoke(app, ["render", "--tracks", str(u["video_det"]), "--video", str(u["video"]), "-o",
                            str(tmp_path / "annotated"), "--gif", str(tmp_path / "preview.out")])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "annotated").read_bytes()[4:8] == b"ftyp"
    assert (tmp_path / "preview.out").read_bytes()[:6] == b"GIF89a"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["annotated", "preview.out"]


def test_write_mot_onto_a_folder_names_the_folder_not_a_temporary_file(tmp_path):
    import numpy as np

    from lookalike.io import write_mot

    folder = tmp_path / "results"
    folder.mkdir()
    with pytest.raises(IsADirectoryError, match=r"is a folder; give a file name: '.*results'") as caught:
        write_mot(folder, np.array([[1, 1, 0, 0, 5, 5, 1, -1, -1, -1.0]]))
    assert ".tmp" not in str(caught.value) and list(tmp_path.iterdir()) == [folder] and not any(folder.iterdir())


def test_track_output_ending_in_a_slash_is_a_folder_not_a_file(tmp_path):
    """``-o newdir/`` for one det.txt wrote a file named ``newdir`` (the option parser dropped the slash)."""
    det = tmp_path / "det.txt"
    det.write_text("".join(DET_ROW.format(f=f, x=10 + f) for f in range(1, 6)))
    r = runner.invoke(app, ["track", str(det), "-o", f"{tmp_path / 'newdir'}/"])
    assert r.exit_code == 2 and r.output.startswith("error: -o/--output") and "ends in '/'" in r.output, r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["det.txt"]
    sequences = tmp_path / "seqs"
    (sequences / "S1" / "det").mkdir(parents=True)
    det.replace(sequences / "S1" / "det" / "det.txt")
    r = runner.invoke(app, ["track", str(sequences), "-o", f"{tmp_path / 'res'}/"])  # a folder of sequences: fine
    assert r.exit_code == 0, r.output
    assert [p.name for p in (tmp_path / "res").iterdir()] == ["S1.txt"]
