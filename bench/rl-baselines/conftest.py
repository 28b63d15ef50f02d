"""Shared pytest fixtures: the exported MDPs the tests run on.

AFFORD_MDP_DIR names a folder of exports to test; otherwise the afford binary
(AFFORD_BIN, default ../../target/release/afford) exports generated scenes
0..AFFORD_MDP_SCENES (default 100) of seed 1 into a temporary folder.
"""

import os
import subprocess
from pathlib import Path

import pytest

import afford_mdp

HERE = Path(__file__).resolve().parent


def afford_bin() -> Path:
    return Path(os.environ.get("AFFORD_BIN", HERE.parent.parent / "target" / "release" / "afford"))


@pytest.fixture(scope="session")
def export_dir(tmp_path_factory) -> Path:
    given = os.environ.get("AFFORD_MDP_DIR")
    if given:
        return Path(given)
    binary = afford_bin()
    if not binary.exists():
        pytest.fail(f"{binary} not found: run `cargo build --release` or set AFFORD_BIN / AFFORD_MDP_DIR")
    out = tmp_path_factory.mktemp("mdp")
    scenes = os.environ.get("AFFORD_MDP_SCENES", "100")
    subprocess.run([str(binary), "export-mdp", "--generated", scenes, "--seed", "1", "-o", str(out)], check=True)
    return out


@pytest.fixture(scope="session")
def mdps(export_dir) -> list:
    found = afford_mdp.load_dir(export_dir)
    assert found, f"no exports in {export_dir}"
    return found
