"""Shared fixtures: the repository, the `afford` command built from it, temp files."""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"


@pytest.fixture(scope="session")
def afford_bin() -> Path:
    """The `afford` command of this checkout (AFFORD_BIN, else target/release/afford)."""
    path = Path(os.environ.get("AFFORD_BIN", REPO / "target" / "release" / "afford"))
    if not path.is_file():
        pytest.fail(f"{path} is missing: build it with `cargo build --release` (or set AFFORD_BIN)")
    return path


def run_afford(afford_bin: Path, *args: str) -> subprocess.CompletedProcess:
    """Runs the command from the repository root; stdout and stderr as text."""
    return subprocess.run([str(afford_bin), *args], cwd=REPO, capture_output=True, text=True, timeout=600)


def afford_json(afford_bin: Path, tmp_path: Path, *args: str) -> tuple[bytes, int]:
    """Runs a command that writes with `-o`; returns the file's bytes and the exit code."""
    out = tmp_path / "out.json"
    done = run_afford(afford_bin, *args, "-o", str(out))
    assert out.is_file(), f"afford {' '.join(args)} wrote nothing: {done.stderr}"
    return out.read_bytes(), done.returncode


def load_json(data: bytes):
    return json.loads(data.decode())
