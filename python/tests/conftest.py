"""Shared helpers: the squeal command-line binary the results are compared with."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def _find_cli():
    env = os.environ.get("SQUEAL_CLI")
    if env:
        return env
    roots = [os.environ.get("CARGO_TARGET_DIR"), REPO / "target"]
    for root in filter(None, roots):
        for profile in ("release", "debug"):
            p = pathlib.Path(root) / profile / "squeal"
            if p.is_file():
                return str(p)
    return None


@pytest.fixture(scope="session")
def cli():
    """Run the CLI (set SQUEAL_CLI, or build it with `cargo build`); returns stdout."""
    exe = _find_cli()
    if exe is None:
        pytest.fail("no squeal binary: build it with `cargo build` or set SQUEAL_CLI")

    def run(*args, cwd=None):
        r = subprocess.run([exe, *args], capture_output=True, text=True, cwd=cwd)
        if r.returncode != 0:
            raise AssertionError(f"squeal {' '.join(args)} failed ({r.returncode}): {r.stderr}")
        return r.stdout

    return run
