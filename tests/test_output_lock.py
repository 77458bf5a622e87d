"""One run at a time in an output folder (``facadecli.export.lock``): with ``flock`` where
``fcntl`` exists, with ``msvcrt.locking`` on a lock file on Windows (here emulated with
POSIX record locks, which conflict between processes as Windows' byte locks do), and
unlocked where there is neither; a second process holds the lock in each test."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from facadecli.errors import SpecError
from facadecli.export import lock

pytestmark = pytest.mark.skipif(os.name == "nt", reason="the holder is a POSIX process")

# the emulated Windows: the same calls msvcrt.locking takes, on POSIX record locks
WINDOWS = """
import fcntl, os
from facadecli.export import lock
class msvcrt:
    LK_UNLCK, LK_NBLCK = 0, 2
    @staticmethod
    def locking(fd, mode, nbytes):
        how = fcntl.LOCK_UN if mode == 0 else fcntl.LOCK_EX | fcntl.LOCK_NB
        fcntl.lockf(fd, how, nbytes, 0, os.SEEK_CUR)
lock.fcntl, lock.msvcrt = None, msvcrt
"""

HOLDER = """
import sys
from pathlib import Path
from facadecli.export import lock
{platform}
with lock.locked(Path(sys.argv[1]), "facade city"):
    print("held", flush=True)
    sys.stdin.readline()
print("released", flush=True)
"""


class Holder:
    """A process that holds the lock on ``folder`` until told to let go (or killed)."""

    def __init__(self, folder: Path, platform: str = ""):
        self.process = subprocess.Popen(
            [sys.executable, "-c", HOLDER.format(platform=platform), str(folder)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self.process.stdout is not None
        assert self.process.stdout.readline() == "held\n"

    def release(self) -> None:
        out, _ = self.process.communicate("go\n", timeout=60)
        assert out == "released\n" and self.process.returncode == 0

    def kill(self) -> None:
        self.process.send_signal(signal.SIGKILL)
        self.process.wait(timeout=60)


def _emulate_windows(monkeypatch: pytest.MonkeyPatch) -> None:
    space: dict[str, object] = {}
    exec(WINDOWS, space)  # the emulation above, the same as the holder's
    monkeypatch.setattr(lock, "msvcrt", space["msvcrt"])
    monkeypatch.setattr(lock, "fcntl", None)


def _busy(folder: Path) -> str:
    with pytest.raises(SpecError) as caught, lock.locked(folder, "facade city"):
        pass
    return str(caught.value)


def test_flock_keeps_a_second_run_out_and_writes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "out"
    holder = Holder(out)
    assert f"another facade city run is writing in '{out}'" in _busy(out)
    assert list(out.iterdir()) == []
    holder.release()
    with lock.locked(out, "facade city"):
        pass


def test_on_windows_a_locked_file_keeps_a_second_run_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _emulate_windows(monkeypatch)
    out = tmp_path / "out"
    holder = Holder(out, WINDOWS)
    assert (out / lock.LOCK_NAME).is_file()
    assert "another facade city run is writing in" in _busy(out)
    assert (out / lock.LOCK_NAME).is_file()  # the refused run leaves the holder's file
    holder.release()
    assert list(out.iterdir()) == []  # the lock file goes with the run
    with lock.locked(out, "facade city"):
        assert [p.name for p in out.iterdir()] == [lock.LOCK_NAME]
    assert list(out.iterdir()) == []


def test_on_windows_a_killed_runs_lock_file_is_taken_over(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _emulate_windows(monkeypatch)
    out = tmp_path / "out"
    Holder(out, WINDOWS).kill()
    assert (out / lock.LOCK_NAME).is_file()  # left, but no process holds it
    with lock.locked(out, "facade city"):
        pass
    assert list(out.iterdir()) == []


def test_a_lock_file_that_is_a_link_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli.errors import OutputError

    _emulate_windows(monkeypatch)
    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "precious").write_text("keep")
    (out / lock.LOCK_NAME).symlink_to(tmp_path / "precious")
    with pytest.raises(OutputError, match="is not a regular file"), lock.locked(out, "x"):
        pass
    assert (tmp_path / "precious").read_text() == "keep"


def test_without_fcntl_or_msvcrt_facadecli_imports_and_runs_unlocked(tmp_path: Path) -> None:
    script = (
        "import sys\n"
        "sys.modules['fcntl'] = sys.modules['msvcrt'] = None  # import fails, as on a bare OS\n"
        "from pathlib import Path\n"
        "import facadecli.cli, facadecli.city.run\n"
        "from facadecli.export import lock\n"
        "assert lock.fcntl is None and lock.msvcrt is None\n"
        "with lock.locked(Path(sys.argv[1]), 'facade city'):\n"
        "    with lock.locked(Path(sys.argv[1]), 'facade city'):\n"
        "        print('unlocked')\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", script, str(tmp_path / "out")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0 and run.stdout == "unlocked\n", run.stderr


def test_a_run_s_own_error_passes_through_the_lock(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError), lock.locked(tmp_path / "out", "facade city"):
        raise FileNotFoundError(2, "the run's own")
