"""The CLI's quick option conversion (lookalike.cli.coercion) gives typer's own values and errors."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import typer.core
from typer._click.exceptions import BadParameter
from typer.main import get_command

from lookalike.cli import app

RAW = ["abc", "1", "-3", "0.05", "1e3", "inf", "-inf", "nan", "", "-", " 2 ", "1_000", "0", "x/y.txt", ".",
       "README.md", "no/such/dir/", ("a", "b"), ["c"], ("README.md", "x/y"), ["-"], (), ("a", 1), 15, 0.5,
       float("-inf"), True, None]


def _outcome(runtime, value, param, ctx):
    try:
        result = runtime.coerce(value, param=param, ctx=ctx)
    except BadParameter as exc:
        return ("error", str(exc.format_message()))
    except (ValueError, TypeError) as exc:
        return ("error", type(exc).__name__)
    return ("value", type(result).__name__, repr(result))


def _parameters():
    group = get_command(app)
    ctx = group.make_context("lookalike", ["--help"], resilient_parsing=True)
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        for param in getattr(command, "params", []):
            if hasattr(param, "type_descriptor"):
                yield name, param


def test_quick_conversion_equals_typers_for_every_option():
    quick = typer.core.build_runtime_param
    full = getattr(quick, "_full_builder", None)
    if full is None:
        pytest.skip("typer's internals differ: the quick conversion is not installed")
    checked = 0
    ctx = get_command(app).make_context("lookalike", ["--help"], resilient_parsing=True)
    for command, param in _parameters():
        fast_param, slow_param = quick(param.type_descriptor), full(param.type_descriptor)
        for value in RAW:
            fast = _outcome(fast_param, value, param, ctx)
            slow = _outcome(slow_param, value, param, ctx)
            assert fast == slow, (command, param.name, value)
            checked += 1
    assert checked > 1000


def test_short_commands_do_not_import_pydantic(tmp_path):
    import subprocess

    code = ("import sys; sys.argv = ['lookalike', 'trackers', '--names']; from lookalike.cli import main\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\n"
            "assert 'pydantic' not in sys.modules, 'pydantic imported'\n"
            "assert 'lookalike.trackers.sort' not in sys.modules, 'a tracker module imported'")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=Path(tmp_path))
    assert run.returncode == 0, run.stderr
    assert "sort" in run.stdout.split()
