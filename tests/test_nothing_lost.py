"""Nothing lost (issue 13, item 1; issue 18, items 3, 5, 8, 9): a full disk, a signal or
another run writing the same output never replaces the previous output with a truncated
or mixed one, never leaves a temporary file, and never exits 0; a report on stdout that
cannot be written is a failure too.

The full-disk tests run on a real small file system: a 256 KiB tmpfs mounted for the
test (CI runs as root); where mounting is not permitted they are skipped with the reason.
"""

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from tools import find_tool, mounted_tmpfs

ROOT = Path(__file__).resolve().parents[1]
CASE3 = ROOT / "input" / "case3.nml"
CASE5 = ROOT / "input" / "case5.nml"
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
    with mounted_tmpfs(tmp_path / "small", f"size={TMPFS_BYTES}") as mount_point:
        yield mount_point


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


def temporaries(folder):
    """Temporary files of any naming (o.dat.part, o.dat.PID-N.part, t.PID-N.part.csv)."""
    return sorted(p.name for p in folder.iterdir() if ".part" in p.name or ".previous" in p.name)


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


# Every signal whose default action ends the process, but SIGKILL (which none can catch):
# gfortran's runtime handles SIGQUIT (a backtrace) and the faults itself unless the guard
# does. SIGSEGV and SIGABRT stand for the faults, SIGRTMIN for the real-time signals.
ENDING_SIGNALS = ["SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT", "SIGUSR1", "SIGUSR2", "SIGALRM",
                  "SIGPIPE", "SIGVTALRM", "SIGPROF", "SIGXCPU", "SIGXFSZ", "SIGSEGV", "SIGABRT",
                  "SIGRTMIN"]


def start_long_run(cli, folder, name="o.dat", scene=CASE3):
    """A CLI run of 5 * 10^6 rows (minutes of writing), returned once it has written to its
    temporary file, so that a signal lands in the middle of the run."""
    proc = subprocess.Popen([cli, str(scene), "--t-end", "5000", "-o", str(folder / name)],
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, start_new_session=True)
    deadline = time.monotonic() + START_TIMEOUT
    while not any(p.stat().st_size > 0 for p in folder.glob(name + "*part")):
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            raise AssertionError(f"the run never started writing: {proc.stderr.read()}")
        time.sleep(0.02)
    return proc


@pytest.mark.parametrize("name", ENDING_SIGNALS)
def test_signal_removes_temporaries(cli, tmp_path, name):
    sig = getattr(signal, name)
    before = previous_output(cli, tmp_path)
    proc = start_long_run(cli, tmp_path)
    try:
        proc.send_signal(sig)
        returncode = proc.wait(timeout=RUN_TIMEOUT)
        stderr = proc.stderr.read().decode(errors="replace")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    # The run dies of the signal as an unguarded one would (a shell shows 128 + signal),
    # without gfortran's backtrace.
    assert returncode == -sig, (returncode, stderr)
    assert "Backtrace" not in stderr and "Program received" not in stderr, stderr
    assert snapshot(tmp_path) == before


def test_concurrent_runs_leave_one_runs_pair(cli, tmp_path):
    """Two runs of different scenes to the same -o (they shared the temporary o.dat.part:
    one exited 0 with the other's samples in place and a mixed events file, the other 2
    with a false "only -1 of N bytes reached the disk"). Each run's pair, written alone,
    is the reference: the pair in place must be one of them, both runs succeed, no
    temporary is left."""
    scenes = {"a": CASE3, "b": CASE5}
    args = ["--t-end", "30"]          # 30001 rows, 7.5 MB: the two runs overlap
    reference = {}
    for key, scene in scenes.items():
        done = run(cli, scene, *args, "-o", tmp_path / f"{key}.dat", cwd=ROOT)
        assert done.returncode == 0, done.stderr
        reference[key] = ((tmp_path / f"{key}.dat").read_bytes(),
                          (tmp_path / f"{key}.events.dat").read_bytes())
    assert reference["a"][0] != reference["b"][0] and reference["a"][1] != reference["b"][1]
    for _ in range(3):
        procs = [subprocess.Popen([cli, str(scene), *args, "-o", str(tmp_path / "o.dat")], cwd=ROOT,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                  stdin=subprocess.DEVNULL) for scene in scenes.values()]
        outcomes = [(proc.wait(timeout=RUN_TIMEOUT), proc.stderr.read()) for proc in procs]
        assert outcomes == [(0, ""), (0, "")]
        pair = ((tmp_path / "o.dat").read_bytes(), (tmp_path / "o.events.dat").read_bytes())
        assert pair in reference.values(), "the pair in place is not one run's"
        assert temporaries(tmp_path) == []


def test_concurrent_whole_writes_keep_one_whole_file(tmp_path):
    """impact1d-sweep's and the plots' writer, two writers at once on one path (threads,
    each held until both have written): they shared one temporary name, the second
    truncated the first's file, and one of them failed to rename it."""
    from impact1d._files import write_whole

    target = tmp_path / "t.csv"
    both_written = threading.Barrier(2, timeout=RUN_TIMEOUT)
    failures = []

    def writer(text):
        def write(temporary):
            with open(temporary, "w") as handle:
                handle.write(text * 1000)
            both_written.wait()

        try:
            write_whole(target, write)
        except Exception as error:     # noqa: BLE001 - the test reports any failure
            failures.append(error)

    threads = [threading.Thread(target=writer, args=(text,)) for text in ("a,b\n", "c,d\n")]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert failures == []
    assert target.read_text() in ("a,b\n" * 1000, "c,d\n" * 1000)
    assert temporaries(tmp_path) == []


def test_concurrent_sweeps_leave_one_whole_table(tmp_path):
    sweep = find_tool("impact1d-sweep")
    grids = {"a": ["--vary", "r_left=0:0.9:40"], "b": ["--vary", "r_right=0:0.9:30"]}
    common = [str(CASE5), "--vary", "t_end=2", "--workers", "1"]
    reference = {}
    for key, grid in grids.items():
        done = subprocess.run([sweep, *common, *grid, "-o", str(tmp_path / f"{key}.csv")],
                              capture_output=True, text=True, timeout=RUN_TIMEOUT)
        assert done.returncode == 0, done.stderr
        reference[key] = (tmp_path / f"{key}.csv").read_bytes()
    for _ in range(3):
        procs = [subprocess.Popen([sweep, *common, *grid, "-o", str(tmp_path / "t.csv")],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                 for grid in grids.values()]
        assert [(proc.wait(timeout=RUN_TIMEOUT), proc.stderr.read()) for proc in procs] == [(0, "")] * 2
        assert (tmp_path / "t.csv").read_bytes() in reference.values()
        assert temporaries(tmp_path) == []


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


# --- the Python commands: interrupted, or with nowhere to report --------------------

# impact1d-sweep's main() in a Python that says on stdout where it is: "ready" once it is
# imported, then `at` when main() reaches `at` (a function of the sweep's modules,
# wrapped), so that SIGINT lands where the test means (2000 runs of case 3 for 200 s each:
# minutes of work). QUIET: the program's own SIGINT handler does not raise (as if Python's
# flag were lost), so only the core's count of the interrupt ends the sweep.
SWEEP_SAYING = """
import signal, sys, impact1d.sweep_cli as cli
if {quiet}:
    signal.signal(signal.SIGINT, lambda *a: None)
module = sys.modules["impact1d.sweep" if "{at}" == "run_chunk" else "impact1d.sweep_cli"]
wrapped = getattr(module, "{at}")
def saying(*args, **kwargs):
    print("{at}", flush=True)
    if {quiet}:
        import time
        time.sleep(1.0)        # the signal comes in here (the quiet handler, then on)
    return wrapped(*args, **kwargs)
setattr(module, "{at}", saying)
print("ready", flush=True)
sys.exit(cli.main(sys.argv[1:]))
"""


def interrupted_sweep(tmp_path, at, quiet=False):
    """The sweep's return code and stderr, SIGINT sent once main() said `at`; the previous
    table and the folder checked as they must be after an interrupt."""
    table = tmp_path / "t.csv"
    table.write_text("the previous table\n")
    code = SWEEP_SAYING.format(at=at, quiet=quiet)
    proc = subprocess.Popen([sys.executable, "-c", code, str(CASE3), "--vary", "r_left=0:0.95:2000",
                             "--vary", "t_end=200", "--workers", "1", "-o", str(table)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline() == "ready\n", proc.stderr.read()
        assert proc.stdout.readline() == at + "\n", proc.stderr.read()
        proc.send_signal(signal.SIGINT)
        returncode = proc.wait(timeout=RUN_TIMEOUT)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert table.read_text() == "the previous table\n"
    assert temporaries(tmp_path) == []
    return returncode, proc.stderr.read()


def test_interrupted_sweep_is_one_line_and_130(tmp_path):
    """SIGINT once the sweep's first runs are under way (it was sent 0.2 s after "ready",
    which a loaded machine once let through: the sweep ran its 90 s and returned 0)."""
    returncode, stderr = interrupted_sweep(tmp_path, "run_chunk")
    assert returncode == 130, stderr
    assert stderr.count("\n") == 1 and stderr.startswith("impact1d-sweep: interrupted"), stderr


@pytest.mark.parametrize("at", ["load_scene", "run_chunk"])
def test_sweep_interrupted_before_its_runs_ends_without_pythons_flag(tmp_path, at):
    """impact1d-sweep counts SIGINT from main()'s start (interrupt_epoch_now), not from the
    sweep's, so an interrupt while it reads the scene, before any run, ends the runs even if
    Python's KeyboardInterrupt never comes (here a handler of the program's own that does not
    raise; before, the sweep ran all its runs and returned 0)."""
    returncode, stderr = interrupted_sweep(tmp_path, at, quiet=True)
    assert returncode == 130, stderr
    assert stderr.count("\n") == 1 and stderr.startswith("impact1d-sweep: interrupted"), stderr


def run_with_stdout(command, stdout, cwd=ROOT):
    """Run a command with stdout on /dev/full ('full') or closed ('closed')."""
    if stdout == "closed":
        command = ["sh", "-c", 'exec "$@" >&-', "sh", *command]
    with open(os.devnull if stdout == "closed" else "/dev/full", "w") as sink:
        return subprocess.run(list(map(str, command)), cwd=cwd, stdout=sink, stderr=subprocess.PIPE,
                              text=True, timeout=RUN_TIMEOUT, stdin=subprocess.DEVNULL,
                              env={**os.environ, "MPLBACKEND": "Agg"})


def assert_one_line_failure(done, prog, status):
    assert done.returncode == status, (done.returncode, done.stderr)
    assert done.stderr.count("\n") == 1 and done.stderr.startswith(prog + ": "), done.stderr
    assert "stdout" in done.stderr and "Traceback" not in done.stderr


@pytest.mark.parametrize("stdout", ["full", "closed"])
def test_cli_summary_that_cannot_be_written_fails(cli, tmp_path, stdout):
    """gfortran's writes to stdout report no error: the run exited 0 with its summary lost."""
    done = run_with_stdout([cli, CASE3, "--dt-out", "0.5", "-o", tmp_path / "o.dat"], stdout)
    assert_one_line_failure(done, "impact1d", 2)
    assert "o.dat is in place" in done.stderr
    assert sorted(snapshot(tmp_path)) == ["o.dat", "o.events.dat"]


@pytest.mark.parametrize("stdout", ["full", "closed"])
def test_sweep_and_plot_reports_that_cannot_be_written_fail(cli, tmp_path, stdout):
    done = run_with_stdout([find_tool("impact1d-sweep"), CASE5, "--vary", "r_left=0,0.5",
                            "--vary", "t_end=1", "-o", tmp_path / "t.csv"], stdout)
    assert_one_line_failure(done, "impact1d-sweep", 2)
    assert (tmp_path / "t.csv").is_file()
    assert run(cli, CASE3, "--dt-out", "0.5", "-o", tmp_path / "o.dat", cwd=ROOT).returncode == 0
    for args in ([tmp_path / "o.dat"], [tmp_path / "t.csv", "--x", "r_left"]):
        done = run_with_stdout([find_tool("impact1d-plot"), *args], stdout)
        assert_one_line_failure(done, "impact1d-plot", 1)


def test_a_lock_held_too_long_ends_the_wait(cli, tmp_path):
    """A run waited for its folder's lock (flock) without end: a holder stopped while
    putting its output in place (SIGSTOP, a suspended job) hung every later run there.
    The wait is bounded (IMPACT1D_LOCK_WAIT seconds, default 60): then status 2, one line
    saying why, no temporary file, the previous pair untouched. Here this test holds the
    lock as such a holder would."""
    import fcntl

    before = previous_output(cli, tmp_path)
    folder = os.open(tmp_path, os.O_RDONLY)
    try:
        fcntl.flock(folder, fcntl.LOCK_EX)
        done = subprocess.run([cli, str(CASE3), "--dt-out", "0.05", "-o", str(tmp_path / "o.dat")], cwd=ROOT,
                              capture_output=True, text=True, timeout=30, stdin=subprocess.DEVNULL,
                              env={**os.environ, "IMPACT1D_LOCK_WAIT": "0.5"})
        assert_refused_and_untouched(done, tmp_path, before)
        assert "another process has held the lock on its folder for 0.5 s" in done.stderr
        # A lock released within the wait is waited for, as before.
        releaser = threading.Timer(0.3, fcntl.flock, (folder, fcntl.LOCK_UN))
        releaser.start()
        done = run(cli, CASE3, "--dt-out", "0.05", "-o", tmp_path / "o.dat", cwd=ROOT)
        releaser.join()
        assert done.returncode == 0, done.stderr
        assert snapshot(tmp_path) != before and temporaries(tmp_path) == []
    finally:
        os.close(folder)


# The sweep's CSV writer, made to receive a signal half-way through its write: the moment
# a SIGTERM or SIGHUP (a closed terminal, a batch system's end of time) would find it.
SWEEP_SIGNALLED_IN_WRITE = """
import os, signal, sys
import pandas as pd
import impact1d.sweep_cli as cli
to_csv = pd.DataFrame.to_csv
def to_csv_then_signal(self, path, **options):
    to_csv(self.head(1), path, **options)
    os.kill(os.getpid(), getattr(signal, sys.argv[1]))
    to_csv(self, path, **options)
pd.DataFrame.to_csv = to_csv_then_signal
sys.exit(cli.main(sys.argv[2:]))
"""


@pytest.mark.parametrize("name", ["SIGTERM", "SIGHUP"])
def test_sweep_signalled_in_its_write_leaves_no_temporary(tmp_path, name):
    """SIGTERM or SIGHUP while impact1d-sweep wrote its table killed it with the temporary
    file (t.PID-N.part.csv) left beside the table. The signal now ends it as before (it
    dies of that signal), after removing the temporary; the previous table stays."""
    table = tmp_path / "t.csv"
    table.write_text("the previous table\n")
    done = subprocess.run([sys.executable, "-c", SWEEP_SIGNALLED_IN_WRITE, name, str(CASE3), "--vary",
                           "r_left=0.5,0.9", "-o", str(table)], capture_output=True, text=True,
                          timeout=RUN_TIMEOUT)
    assert done.returncode == -getattr(signal, name), (done.returncode, done.stderr)
    assert table.read_text() == "the previous table\n"
    assert temporaries(tmp_path) == []
    assert done.stderr.startswith(f"impact1d-sweep: ended by {name}") and done.stderr.count("\n") == 1


PLOT_SIGNALLED_IN_WRITE = """
import os, signal, sys
import matplotlib
matplotlib.use("Agg")
from matplotlib.figure import Figure
import impact1d.plot_cli as cli
savefig = Figure.savefig
def savefig_then_signal(self, path, **options):
    with open(path, "wb") as part:
        part.write(b"half an image")
    os.kill(os.getpid(), getattr(signal, sys.argv[1]))
    savefig(self, path, **options)
Figure.savefig = savefig_then_signal
sys.exit(cli.main(sys.argv[2:]))
"""


def test_plot_signalled_in_its_write_leaves_no_temporary(cli, tmp_path):
    """The same for impact1d-plot's image."""
    previous_output(cli, tmp_path)
    image = tmp_path / "o.png"
    image.write_bytes(b"the previous image")
    done = subprocess.run([sys.executable, "-c", PLOT_SIGNALLED_IN_WRITE, "SIGTERM", str(tmp_path / "o.dat")],
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == -signal.SIGTERM, (done.returncode, done.stderr)
    assert image.read_bytes() == b"the previous image" and temporaries(tmp_path) == []
    assert done.stderr == "impact1d-plot: ended by SIGTERM\n"
