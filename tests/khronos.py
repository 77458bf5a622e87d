"""The Khronos glTF validator (``make test`` installs it with npm in the venv), run by
node on glb files: its report of each, and the check that each is clean."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

VALIDATOR = Path(sys.prefix) / "node" / "node_modules"
SCRIPT = Path(__file__).resolve().parent / "gltf_validate.js"


def reports(*files: Path) -> list[dict[str, Any]]:
    """The validator's report of each of ``files``, in their order."""
    done = subprocess.run(
        ["node", str(SCRIPT), str(VALIDATOR), *map(str, files)],
        capture_output=True,
        text=True,
        check=True,
    )
    return [json.loads(line) for line in done.stdout.splitlines()]


def validates(*files: Path) -> None:
    """The validator finds no error and no warning in any of ``files``."""
    found = reports(*files)
    assert len(found) == len(files), found
    for report in found:
        assert (report["errors"], report["warnings"]) == (0, 0), report
