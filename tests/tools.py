"""Where the tests find the command-line tools: beside the running interpreter first, so
that `.venv/bin/python -m pytest tests` tests that environment's install without an
activated venv (or a PATH that leads elsewhere). And a small file system mounted for a
test (a full disk, a read-only one)."""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import sysconfig
from importlib import metadata
from pathlib import Path

import pytest


def find_tool(name: str) -> str:
    """Absolute path of the installed executable `name` (impact1d, impact1d-plot).
    Looks in the interpreter's scripts folder, the folder of sys.executable (not resolved:
    a venv's python is a link to the system one), the files the installed impact1d package
    recorded, then PATH. A missing tool is an AssertionError (a failure, never a skip)."""
    exe = name + (".exe" if os.name == "nt" else "")
    folders = [sysconfig.get_path("scripts"), os.path.dirname(sys.executable)]
    for folder in folders:
        candidate = Path(folder) / exe
        if candidate.is_file() and os.access(candidate, os.X_OK):
            return str(candidate)
    try:
        for entry in metadata.distribution("impact1d").files or ():
            if Path(entry).name == exe:
                candidate = Path(entry.locate()).resolve()
                if candidate.is_file() and os.access(candidate, os.X_OK):
                    return str(candidate)
    except metadata.PackageNotFoundError:
        pass
    found = shutil.which(name)
    assert found is not None, (
        f"the {name} executable is neither beside {sys.executable} nor recorded by the "
        f"installed impact1d package nor on PATH: install the package (make setup)")
    return found


@contextlib.contextmanager
def mounted_tmpfs(folder: Path, options: str):
    """A tmpfs mounted on folder (made here) with the given mount options, always
    unmounted afterwards; the test is skipped with the reason where mounting is not
    permitted (CI runs as root)."""
    folder.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs ({options}) here: {done.stderr.strip() or done.returncode}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


def wall_records(scene, right_body: int) -> list:
    """A tutorial Scene's walls as &contact records: the left wall on body 1, the right wall
    on body `right_body`, named as the engine names them (restitution 1 when not given)."""
    def given(name, default):
        value = getattr(scene, name)
        return default if value is None else value

    contacts = []
    if scene.x_left is not None:
        contacts.append(dict(a=0, b=1, d_min=scene.x_left, r_min=given("r_left", 1.0), name="left"))
    if scene.x_right is not None:
        contacts.append(dict(a=0, b=right_body, d_max=scene.x_right, r_max=given("r_right", 1.0), name="right"))
    return contacts
