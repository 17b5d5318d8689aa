"""The README's and the docs' shell commands work as written.

Every ``lookalike ...`` command in a shell code block of README.md or docs/**/*.md is parsed by the
CLI itself: the (sub)command must exist and its options and arguments must parse (names, types,
required options), as ``lookalike`` would parse them before doing any work. Shell variables (``$J``)
stand for a value that parses. Blocks preceded by the line ``<!-- doc-test: run -->`` are also run,
in document order, in one temporary folder beside a link to ``../shared/data`` and to the
repository's ``demo-out/`` (commands needing either skip when it is absent); blocks marked
``<!-- doc-test: run slow -->`` run only with ``LOOKALIKE_DOC_TEST_SLOW=1``. Commands run in-process
through typer's test runner. Python blocks preceded by the same marker run too, in the same folder
(``exec``, after the shell blocks of the same documents).
"""

from __future__ import annotations

import os
import re
import shlex
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
DOC_FILES = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
SHELL_LANGS = {"sh", "bash", "shell", "console"}
MARKER = re.compile(r"<!--\s*doc-test:\s*run(\s+slow)?\s*-->")
RUN_SLOW = os.environ.get("LOOKALIKE_DOC_TEST_SLOW") == "1"
# How the docs call the CLI: the entry point, its path in the venv, or the module.
PREFIXES = (("lookalike",), (".venv/bin/lookalike",), ("python", "-m", "lookalike"),
            (".venv/bin/python", "-m", "lookalike"))
SEPARATORS = {";", "&", "&&", "|", "||", "(", ")", "do", "done", "then", "fi"}


@dataclass(frozen=True)
class Command:
    """One ``lookalike`` invocation found in a document: where, and its arguments after the prefix."""

    doc: Path
    line: int  # 1-based line of the block's first line
    args: tuple[str, ...]
    mode: str  # "check", "run" or "slow"

    @property
    def where(self) -> str:
        return f"{self.doc.relative_to(REPO)}:{self.line}"

    def __str__(self) -> str:
        return f"{self.where}: lookalike {' '.join(self.args)}"


def shell_blocks(doc: Path) -> list[tuple[int, str, str]]:
    """``(first line, text, mode)`` of every shell code block in ``doc``."""
    return code_blocks(doc, SHELL_LANGS)


def code_blocks(doc: Path, langs: set[str]) -> list[tuple[int, str, str]]:
    """``(first line, text, mode)`` of every code block of a language in ``langs`` in ``doc``."""
    lines = doc.read_text(encoding="utf-8").splitlines()
    blocks, i = [], 0
    while i < len(lines):
        fence = re.match(r"^(\s*)(```+)\s*(\w*)", lines[i])
        if not fence:
            i += 1
            continue
        indent, ticks, lang = fence.groups()
        body, j = [], i + 1
        while j < len(lines) and not lines[j].strip().startswith(ticks):
            body.append(lines[j][len(indent):] if lines[j].startswith(indent) else lines[j])
            j += 1
        if lang in langs:
            k = i - 1
            while k >= 0 and not lines[k].strip():
                k -= 1
            marker = MARKER.search(lines[k]) if k >= 0 else None
            mode = "check" if marker is None else ("slow" if marker.group(1) else "run")
            blocks.append((i + 2, "\n".join(body), mode))
        i = j + 1
    return blocks


def split_commands(text: str) -> list[tuple[str, ...]]:
    """The ``lookalike`` invocations of a shell block, arguments after the prefix."""
    text = re.sub(r"\\\n", " ", text)  # line continuations
    found = []
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("$ "):
            line = line[2:]
        lexer = shlex.shlex(line, posix=True, punctuation_chars=";&|()")
        lexer.whitespace_split = True
        lexer.commenters = "#"
        try:
            tokens = list(lexer)
        except ValueError as e:  # an unbalanced quote is a documentation error
            raise AssertionError(f"cannot split shell line {line!r}: {e}") from e
        k = 0
        while k < len(tokens):
            for prefix in PREFIXES:
                if tuple(tokens[k:k + len(prefix)]) == prefix:
                    start = k + len(prefix)
                    end = start
                    while end < len(tokens) and tokens[end] not in SEPARATORS:
                        end += 1
                    found.append(tuple(tokens[start:end]))
                    k = end
                    break
            else:
                k += 1
    return found


def all_commands() -> list[Command]:
    return [Command(doc, line, args, mode)
            for doc in DOC_FILES for line, text, mode in shell_blocks(doc) for args in split_commands(text)]


COMMANDS = all_commands()


def _cli():
    import typer.main

    from lookalike.cli import app

    return app, typer.main.get_command(app)


def check_parses(cmd: Command) -> None:
    """Resolve the sub-command and parse the arguments as the CLI would, without running it."""
    _, group = _cli()
    args = [("1" if "$" in a else a) for a in cmd.args]
    command, path, parent = group, ["lookalike"], None
    while hasattr(command, "commands") and args and not args[0].startswith("-"):
        name = args.pop(0)
        sub = command.commands.get(name)
        assert sub is not None, (f"{cmd}: no command {' '.join(path)} {name} "
                                 f"(there are: {', '.join(sorted(command.commands))})")
        path.append(name)
        command = sub
    if "--help" in args or "--version" in args:
        names = {opt for p in command.params for opt in (*p.opts, *p.secondary_opts)}
        flag = "--help" if "--help" in args else "--version"
        assert flag == "--help" or flag in names, f"{cmd}: {' '.join(path)} has no {flag}"
        return
    assert not hasattr(command, "commands"), f"{cmd}: {' '.join(path)} needs a sub-command"
    try:
        command.make_context(path[-1], list(args), parent=parent)
    except Exception as e:  # the CLI's usage errors: no such option, bad value, missing option
        raise AssertionError(f"{cmd}: {type(e).__name__}: {e}") from e


def test_documents_have_commands():
    """The scan finds the README's recipes and the docs' commands (guards against a parser that finds none)."""
    readme = [c for c in COMMANDS if c.doc.name == "README.md"]
    assert len(readme) >= 6, readme
    assert len(COMMANDS) >= 40, len(COMMANDS)
    assert any(c.mode == "run" for c in readme)


def test_readme_is_one_page():
    lines = (REPO / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 150, f"README.md has {len(lines)} lines (a one-page quickstart has at most 150)"


@pytest.mark.parametrize("cmd", COMMANDS, ids=[f"{c.where}:{' '.join(c.args[:2])}" for c in COMMANDS])
def test_command_parses(cmd: Command):
    check_parses(cmd)


def test_readme_links_exist():
    """The README's relative links (into docs/) name files that exist (the site build checks the docs' own)."""
    text = (REPO / "README.md").read_text(encoding="utf-8")
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue
        path = target.split("#", 1)[0]
        assert (REPO / path).exists(), f"README.md links to {target}, which does not exist"


def test_make_targets_and_extras_exist():
    """``make X`` names a Makefile target and ``.[extra]`` / ``lookalike[extra]`` an extra of pyproject.toml."""
    makefile = (REPO / "Makefile").read_text(encoding="utf-8")
    targets = set(re.findall(r"^([\w.-]+):", makefile, flags=re.M))
    pyproject = (REPO / "pyproject.toml").read_text(encoding="utf-8")
    section = pyproject.split("[project.optional-dependencies]", 1)[1].split("\n[", 1)[0]
    extras = set(re.findall(r"^([\w-]+)\s*=", section, flags=re.M))
    for doc in DOC_FILES:
        for _, text, _ in shell_blocks(doc):
            for target in re.findall(r"(?:^|[;&]\s*)make\s+([\w.-]+)", text, flags=re.M):
                assert target in targets, f"{doc.relative_to(REPO)}: no Makefile target {target!r}"
        for names in re.findall(r"(?:\.|lookalike)\[([\w,-]+)\]", doc.read_text(encoding="utf-8")):
            for name in names.split(","):
                assert name in extras, f"{doc.relative_to(REPO)}: pyproject.toml has no extra {name!r}"


def test_benchmark_scripts_exist():
    """``python benchmarks/X.py`` in the docs names a script that exists."""
    for doc in DOC_FILES:
        for name in re.findall(r"benchmarks/([\w-]+\.py)", doc.read_text(encoding="utf-8")):
            assert (REPO / "benchmarks" / name).is_file(), f"{doc.relative_to(REPO)}: benchmarks/{name} does not exist"


# --- running the marked blocks -------------------------------------------------------------------

RUNNABLE = [c for c in COMMANDS if c.mode in ("run", "slow")]
_WORK: list[Path] = []  # the one working folder, made on first use
_DONE: set[tuple[str, ...]] = set()  # commands already run there (the README repeats the guides' commands)


def _workdir(factory: pytest.TempPathFactory) -> Path:
    """The working folder every marked block runs in, in document order; ``../shared`` and
    ``demo-out`` link to the real ones where they exist."""
    if not _WORK:
        root = factory.mktemp("doc-commands")
        work = root / "work"
        work.mkdir()
        if SHARED.is_dir():
            (root / "shared").symlink_to(SHARED, target_is_directory=True)
        if (REPO / "demo-out").is_dir():
            (work / "demo-out").symlink_to(REPO / "demo-out", target_is_directory=True)
        _WORK.append(work)
    return _WORK[0]


@pytest.mark.parametrize("cmd", RUNNABLE, ids=[f"{c.where}:{' '.join(c.args[:2])}" for c in RUNNABLE])
def test_command_runs(cmd: Command, tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch):
    if cmd.mode == "slow" and not RUN_SLOW:
        pytest.skip("a slow documented command: set LOOKALIKE_DOC_TEST_SLOW=1 to run it")
    joined = " ".join(cmd.args)
    if "../shared/" in joined and not (SHARED / "data").is_dir():
        pytest.skip(f"needs {SHARED / 'data'}, which is absent")
    if "demo-out/" in joined and not (REPO / "demo-out").is_dir():
        pytest.skip("needs demo-out/ from `make demo`")
    from typer.testing import CliRunner

    app, _ = _cli()
    if cmd.args in _DONE:
        return  # the same command, already run with the same inputs in the same folder
    monkeypatch.chdir(_workdir(tmp_path_factory))
    result = CliRunner().invoke(app, list(cmd.args))
    if result.exit_code != 0:
        detail = result.output[-3000:]
        if result.exception is not None and not isinstance(result.exception, SystemExit):
            import traceback

            detail += "".join(traceback.format_exception(result.exception))[-3000:]
        pytest.fail(f"{cmd} exited with {result.exit_code} in {Path.cwd()}:\n{detail}")
    _DONE.add(cmd.args)


PYTHON_BLOCKS = [(doc, line, text, mode) for doc in DOC_FILES for line, text, mode in code_blocks(doc, {"python"})
                 if mode in ("run", "slow")]


@pytest.mark.parametrize("doc, line, text, mode", PYTHON_BLOCKS,
                         ids=[f"{d.relative_to(REPO)}:{n}" for d, n, _, _ in PYTHON_BLOCKS])
def test_python_block_runs(doc: Path, line: int, text: str, mode: str, tmp_path_factory: pytest.TempPathFactory,
                           monkeypatch: pytest.MonkeyPatch):
    """A marked Python block runs as written, in the folder where the marked shell blocks run."""
    if mode == "slow" and not RUN_SLOW:
        pytest.skip("a slow documented block: set LOOKALIKE_DOC_TEST_SLOW=1 to run it")
    if "../shared/" in text and not (SHARED / "data").is_dir():
        pytest.skip(f"needs {SHARED / 'data'}, which is absent")
    monkeypatch.chdir(_workdir(tmp_path_factory))
    exec(compile(text, f"{doc.relative_to(REPO)}:{line}", "exec"), {"__name__": "__doc_test__"})


def test_readme_python_example_is_run():
    """The README's Python example is marked to run (so it cannot rot unnoticed)."""
    assert any(doc.name == "README.md" for doc, _, _, _ in PYTHON_BLOCKS)
