"""Nothing lost (issue 13, item 1): a full disk or a signal never replaces the previous
output with a truncated one, never leaves a temporary file, and never exits 0.

The full-disk tests run on a real small file system: a 256 KiB tmpfs mounted for the
test (CI runs as root); where mounting is not permitted they are skipped with the reason.
"""

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from tools import find_tool

ROOT = Path(__file__).resolve().parents[1]
CASE3 = ROOT / "input" / "case3.nml"
# A CLI run of a seed case on a busy 2-core machine takes well under this.
RUN_TIMEOUT = 120
# How long to wait for a long run to open its temporary file before giving up.
START_TIMEOUT = 60
TMPFS_BYTES = 256 * 1024


@pytest.fixture
def cli():
    return find_tool("impact1d")


@pytest.fixture
def small_disk(tmp_path):
    """A 256 KiB tmpfs, always unmounted afterwards."""
    mount_point = tmp_path / "small"
    mount_point.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={TMPFS_BYTES}", "tmpfs",
                           str(mount_point)], capture_output=True, text=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here: {done.stderr.strip() or done.returncode}")
    try:
        yield mount_point
    finally:
        subprocess.run(["umount", str(mount_point)], check=True)


def fill_disk(folder):
    """Take every free byte of folder's file system with a file named fill."""
    try:
        with open(folder / "fill", "wb", buffering=0) as fill:
            while True:
                fill.write(b"\0" * 4096)
    except OSError:
        pass      # the disk is full: that is the point
    assert os.statvfs(folder).f_bavail == 0


def run(cli, *args, cwd):
    return subprocess.run([cli, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=RUN_TIMEOUT, stdin=subprocess.DEVNULL)


def snapshot(folder):
    """Every file in folder with its bytes."""
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def previous_output(cli, folder):
    """A small complete o.dat / o.events.dat pair (61 rows) that later runs must not harm."""
    done = run(cli, CASE3, "--dt-out", "0.1", "-o", folder / "o.dat", cwd=ROOT)
    assert done.returncode == 0, done.stderr
    files = snapshot(folder)
    assert set(files) >= {"o.dat", "o.events.dat"} and files["o.events.dat"]
    return files


def assert_refused_and_untouched(done, folder, before):
    assert done.returncode == 2, (done.returncode, done.stdout, done.stderr)
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "cannot write output" in lines[0] and "o.dat" in lines[0]
    assert ".part" not in done.stderr
    after = {name: data for name, data in snapshot(folder).items() if name != "fill"}
    assert after == before, "the previous output changed or a temporary file was left"


def test_nearly_full_disk_keeps_previous_output(cli, small_disk):
    before = previous_output(cli, small_disk)
    # Case 3 at its own dt_out writes 6001 rows (1.5 MB): far more than is free.
    done = run(cli, CASE3, "-o", small_disk / "o.dat", cwd=ROOT)
    assert_refused_and_untouched(done, small_disk, before)


def test_full_disk_keeps_previous_output(cli, small_disk):
    before = previous_output(cli, small_disk)
    fill_disk(small_disk)
    done = run(cli, CASE3, "--dt-out", "0.5", "-o", small_disk / "o.dat", cwd=ROOT)
    assert_refused_and_untouched(done, small_disk, before)


def test_full_disk_with_no_previous_output_leaves_nothing(cli, small_disk):
    done = run(cli, CASE3, "-o", small_disk / "o.dat", cwd=ROOT)
    assert_refused_and_untouched(done, small_disk, {})


def test_rewrite_replaces_the_pair_and_leaves_no_temporaries(cli, tmp_path):
    previous_output(cli, tmp_path)
    done = run(cli, CASE3, "--dt-out", "0.5", "-o", tmp_path / "o.dat", cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.dat", "o.events.dat"]
    rows = [l for l in (tmp_path / "o.dat").read_text().splitlines() if not l.startswith("#")]
    assert len(rows) == 13      # t = 0, 0.5, ..., 6


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP],
                         ids=["SIGINT", "SIGTERM", "SIGHUP"])
def test_signal_removes_temporaries(cli, tmp_path, sig):
    before = previous_output(cli, tmp_path)
    # 5 * 10^6 rows: minutes of writing, so the signal lands in the middle of the run.
    proc = subprocess.Popen([cli, str(CASE3), "--t-end", "5000", "-o", str(tmp_path / "o.dat")],
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.monotonic() + START_TIMEOUT
        part = tmp_path / "o.dat.part"
        while not (part.exists() and part.stat().st_size > 0):
            assert proc.poll() is None, proc.stderr.read()
            assert time.monotonic() < deadline, "the run never started writing"
            time.sleep(0.02)
        proc.send_signal(sig)
        returncode = proc.wait(timeout=RUN_TIMEOUT)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    # The run dies of the signal as an unguarded one would (a shell shows 128 + signal).
    assert returncode == -sig
    assert snapshot(tmp_path) == before


def test_plot_on_full_disk_keeps_previous_image(small_disk):
    import impact1d
    from impact1d import plot
    result = impact1d.simulate(impact1d.load_scene(CASE3), dt_out=0.1)
    png = small_disk / "case3.png"
    png.write_bytes(b"previous image")
    fill_disk(small_disk)
    with pytest.raises(OSError):
        plot.save(result, png)
    assert png.read_bytes() == b"previous image"
    assert sorted(p.name for p in small_disk.iterdir()) == ["case3.png", "fill"]
