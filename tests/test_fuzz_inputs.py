"""Mutated scene files (issue 13, "Done when"): whatever the bytes, the outcome is a run
with finite numbers, or an InputError / SimulationError with a one-line message; never
another exception, a crash or a hang. Seeded, so a failure reproduces."""

import os
import random
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import impact1d
from tools import find_tool

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"
SEED = 20261123
N_MUTATIONS = 300
N_CLI = 40
RUN_TIMEOUT = 60
# Runs are cut short (the outcome classes show in the first steps); a mutated dt far below
# this would only make a legitimately long run, not a fault.
T_END = 0.02
DT_FLOOR = 1e-5

EXTREMES = ["1e308", "-1e308", "1.7976931348623157e308", "5e-324", "-0.0", "nan", "inf",
            "-inf", "0", "1e-300", "123456789012345678901234567890", "+", "-", "1e", ".",
            "2*3", "'x'", "1,2", "9" * 400]
JUNK = ["\x00", "\x1b[2J", "\x07", "é", "Δ", "/", "&", "!", "'", '"', " " * 5000, "\t", "&run",
        "&end", "$"]


def sources():
    files = sorted(INPUT.glob("case*.nml")) + sorted(INPUT.glob("input*.dat"))
    return [(path.suffix, path.read_text()) for path in files]


def mutate(rng, text):
    lines = text.splitlines(keepends=True)
    for _ in range(rng.randint(1, 3)):
        kind = rng.randrange(7)
        if kind == 0 and text:                                   # flip a byte
            i = rng.randrange(len(text))
            text = text[:i] + chr(rng.randrange(1, 128)) + text[i + 1:]
        elif kind == 1 and lines:                                # delete a line
            del lines[rng.randrange(len(lines))]
            text = "".join(lines)
        elif kind == 2 and lines:                                # duplicate a line
            i = rng.randrange(len(lines))
            lines.insert(i, lines[i])
            text = "".join(lines)
        elif kind == 3:                                          # a number -> an extreme
            words = text.split(" ")
            candidates = [i for i, w in enumerate(words) if any(c.isdigit() for c in w)]
            if candidates:
                i = rng.choice(candidates)
                tail = "".join(c for c in words[i] if c in ",/\n")
                words[i] = rng.choice(EXTREMES) + tail
            text = " ".join(words)
        elif kind == 4:                                          # truncate
            text = text[:rng.randrange(len(text) + 1)]
        elif kind == 5:                                          # insert junk
            i = rng.randrange(len(text) + 1)
            text = text[:i] + rng.choice(JUNK) + text[i:]
        else:                                                    # a long line
            i = rng.randrange(len(text) + 1)
            text = text[:i] + " " * rng.choice([4095, 4096, 4097, 10000]) + text[i:]
        lines = text.splitlines(keepends=True)
    return text


def mutations():
    rng = random.Random(SEED)
    base = sources()
    for n in range(N_MUTATIONS):
        suffix, text = rng.choice(base)
        yield n, suffix, mutate(rng, text)


def one_line(error):
    message = str(error)
    return bool(message) and "\n" not in message and not any(ord(c) < 32 for c in message)


def test_mutated_scenes_through_python(tmp_path):
    (tmp_path / "triangle.dat").write_text((INPUT / "triangle.dat").read_text())
    outcomes = {"ran": 0, "InputError": 0, "SimulationError": 0}
    for n, suffix, text in mutations():
        path = tmp_path / f"m{n}{suffix}"
        path.write_bytes(text.encode("utf-8", errors="surrogateescape"))
        try:
            scene = impact1d.load_scene(path)
            dt = scene.dt if scene.dt is not None and scene.dt == scene.dt else DT_FLOOR
            res = impact1d.simulate(scene, t_end=T_END, dt=max(dt, DT_FLOOR), dt_out=None)
        except (impact1d.InputError, impact1d.SimulationError) as error:
            assert one_line(error), f"mutation {n}: {error!r}"
            outcomes[type(error).__name__] += 1
            continue
        assert all(np.all(np.isfinite(getattr(res, c))) for c in res.columns), f"mutation {n}"
        assert np.isfinite(res.energy_residual)
        outcomes["ran"] += 1
    # The mutations reach both the runs and the refusals.
    assert outcomes["ran"] > 10 and outcomes["InputError"] > 10, outcomes


def test_mutated_scenes_through_the_cli(tmp_path):
    cli = find_tool("impact1d")
    (tmp_path / "triangle.dat").write_text((INPUT / "triangle.dat").read_text())
    for n, suffix, text in list(mutations())[:N_CLI]:
        path = tmp_path / f"c{n}{suffix}"
        path.write_bytes(text.encode("utf-8", errors="surrogateescape"))
        args = [cli, str(path), "-o", str(tmp_path / f"out{n}.dat"), "--t-end", str(T_END),
                "--dt", str(DT_FLOOR) if suffix == ".dat" else "1e-3"]
        done = subprocess.run(args, capture_output=True, timeout=RUN_TIMEOUT,
                              stdin=subprocess.DEVNULL)
        assert done.returncode in (0, 1, 2), f"mutation {n}: exit {done.returncode}"
        if done.returncode:
            lines = done.stderr.decode("utf-8", errors="replace").strip().splitlines()
            assert len(lines) == 1 and lines[0].startswith("impact1d: "), f"mutation {n}: {lines}"
            assert not any(b < 32 for b in done.stderr.rstrip(b"\n")), f"mutation {n}"


# --- special files (issue 18, item 4): every kind of file in every role ---------------

# What can stand where a file is expected: only a regular file (or a link to one) is read
# or replaced; the others are refused at once, naming the path and what it is. A FIFO,
# /dev/zero as input blocked or read forever; as output, a FIFO or a link was replaced.
KINDS = {"fifo": "FIFO", "device": "character device", "folder": "folder", "socket": "socket",
         "link": None, "link_to_fifo": "FIFO", "dangling_link": "missing file"}
ROLES = ["scene", "dat_scene", "table", "output", "events_output"]
SPECIAL_TIMEOUT = 20


def make_special(folder, name, kind):
    """A file of the given kind at folder/name; a link leads to a regular file (a scene, a
    table or an earlier output, as the role needs) made from `regular`."""
    path = folder / name
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        path.symlink_to("/dev/zero")      # the device itself, under a name of the role's
    elif kind == "folder":
        path.mkdir()
    elif kind == "socket":
        import socket
        server = socket.socket(socket.AF_UNIX)
        server.bind(str(path))
        server.close()
    elif kind == "link_to_fifo":
        os.mkfifo(folder / "real_fifo")
        path.symlink_to("real_fifo")
    elif kind == "dangling_link":
        path.symlink_to("nowhere")
    return path


def describe(path):
    """What a path is now (the link itself, and what it leads to), to show it untouched."""
    st = os.lstat(path)
    target = os.readlink(path) if os.path.islink(path) else None
    return st.st_mode & 0o170000, target


@pytest.mark.parametrize("role", ROLES)
@pytest.mark.parametrize("kind", list(KINDS))
def test_special_files_in_every_role(tmp_path, kind, role):
    cli = find_tool("impact1d")
    scene_text = (INPUT / "case6.nml").read_text()
    table_text = (INPUT / "triangle.dat").read_text()
    names = {"scene": "s.nml", "dat_scene": "s.dat", "table": "triangle.dat",
             "output": "o.dat", "events_output": "o.events.dat"}
    name = names[role]
    if kind == "link":
        # A link to a regular file of the right content, in a folder of its own.
        (tmp_path / "real").mkdir()
        content = {"scene": scene_text, "dat_scene": (INPUT / "input1.dat").read_text(),
                   "table": table_text}.get(role, "an earlier output\n")
        (tmp_path / "real" / name).write_text(content)
        (tmp_path / name).symlink_to(Path("real") / name)
    elif kind == "device" and role in ("output", "events_output"):
        (tmp_path / name).symlink_to("/dev/null")      # /dev/zero is not writable for all
    else:
        make_special(tmp_path, name, kind)
    if role != "scene":
        (tmp_path / "s.nml").write_text(scene_text)
    if role != "table":
        (tmp_path / "triangle.dat").write_text(table_text)
    scene = "s.dat" if role == "dat_scene" else "s.nml"
    before = describe(tmp_path / name)
    done = subprocess.run([cli, scene, "-o", "o.dat", "--t-end", "0.1", "--dt", "1e-3"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=SPECIAL_TIMEOUT,
                          stdin=subprocess.DEVNULL)
    assert describe(tmp_path / name) == before, "the special file was replaced"
    if kind == "link":
        assert done.returncode == 0, done.stderr
        if role in ("output", "events_output"):      # written through the link
            assert (tmp_path / "real" / name).read_text().startswith("# impact1d")
        return
    assert done.returncode == 1, (done.returncode, done.stdout, done.stderr)
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and name in lines[0] and KINDS[kind] in lines[0], lines
    # Nothing written: no output, no temporary file.
    assert not any(p.name.startswith("o.") and p.name != name for p in tmp_path.iterdir())


# --- concurrent writers (issue 18, item 3) -------------------------------------------

N_WRITERS = 3
N_ROUNDS = 2


def test_concurrent_writers_of_one_output(tmp_path):
    """Several runs of different scenes to one -o at once: each succeeds, the pair in place
    is one run's own (as it writes it alone), and no temporary file is left."""
    cli = find_tool("impact1d")
    rng = random.Random(SEED)
    scenes = sorted(INPUT.glob("case*.nml"))
    args = ["--t-end", "10"]
    reference = {}
    for scene in scenes:
        done = subprocess.run([cli, str(scene), *args, "-o", str(tmp_path / "ref.dat")],
                              capture_output=True, timeout=RUN_TIMEOUT, stdin=subprocess.DEVNULL)
        assert done.returncode == 0, done.stderr
        reference[scene.name] = ((tmp_path / "ref.dat").read_bytes(),
                                 (tmp_path / "ref.events.dat").read_bytes())
    for _ in range(N_ROUNDS):
        chosen = rng.sample(scenes, N_WRITERS)
        procs = [subprocess.Popen([cli, str(scene), *args, "-o", str(tmp_path / "o.dat")],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                  stdin=subprocess.DEVNULL) for scene in chosen]
        assert [(p.wait(timeout=RUN_TIMEOUT), p.stderr.read()) for p in procs] == [(0, b"")] * N_WRITERS
        pair = ((tmp_path / "o.dat").read_bytes(), (tmp_path / "o.events.dat").read_bytes())
        assert pair in [reference[scene.name] for scene in chosen]
        assert sorted(p.name for p in tmp_path.iterdir()) == ["o.dat", "o.events.dat", "ref.dat",
                                                              "ref.events.dat"]


# --- issue 18: families whose outcome is known -------------------------------------------
# Each mutation below has one right answer: a named refusal (a null or a duplicate value, a
# broken .dat line), or the scene read exactly as meant (quoted '&', '/', ',' in a title or
# a table path, a harmless reformatting of a .dat number).

N_FAMILY = 40
ASSIGNMENT = re.compile(r"(\b[a-z_][a-z0-9_]*)(\s*=\s*)('[^']*'|[^,/\s]+)")
NULLS = ["{name} = ", "{name} = 1*", "{name}", "{name} =  "]
TITLE_PIECES = ["&initial x1 = 5.0 /", "&run", "/", "$end", "&end", ",", ";", "=", "!", "'",
                '"', "x2 = 9", " ", "abc", "&", "$", "1*", "&bodies m1 = 0 /"]
PATH_PIECES = ["&", "$", "!", ",", ";", "=", "'", "&run ", "&run dt = 1 ", "&initial ", "end", "a b", "x"]
DAT_BAD = [",", "1*", ", 5", "5 5", "5 /", "/", "2*3", "x", "5,,", "1 , ,"]
DAT_SAME = ["  {v}  ", "{v}e0", "{v}  # a note", "{v}d0"]


def assignments(text):
    """(line number, start, end, name) of every 'name = value' in the scene's groups."""
    found = []
    for number, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("!"):
            continue
        found += [(number, m.start(), m.end(), m.group(1)) for m in ASSIGNMENT.finditer(line)]
    return found


def scene_of(path):
    """A loaded scene's fields but its source."""
    return {k: v for k, v in vars(impact1d.load_scene(path)).items() if k != "source"}


def seeded(family):
    return random.Random(f"{SEED}-{family}")


def test_null_values_are_refused_naming_variable_and_line(tmp_path):
    rng = seeded("null")
    for n in range(N_FAMILY):
        case = rng.choice(sorted(INPUT.glob("case*.nml")))
        lines = case.read_text().splitlines()
        number, start, end, name = rng.choice(assignments(case.read_text()))
        line = lines[number - 1]
        lines[number - 1] = line[:start] + rng.choice(NULLS).format(name=name) + line[end:]
        path = tmp_path / f"null{n}.nml"
        path.write_text("\n".join(lines) + "\n")
        with pytest.raises(impact1d.InputError, match=re.escape(f"null{n}.nml:{number}: ") + f".*{name}.* has no value"):
            impact1d.load_scene(path)


def test_duplicate_values_are_refused_naming_both_lines(tmp_path):
    rng = seeded("duplicate")
    for n in range(N_FAMILY):
        case = rng.choice(sorted(INPUT.glob("case*.nml")))
        text = case.read_text()
        lines = text.splitlines()
        number, start, end, name = rng.choice(assignments(text))
        copy = lines[number - 1][start:end]
        if rng.random() < 0.5:                                   # on the same line
            lines[number - 1] = lines[number - 1][:end] + ", " + copy + lines[number - 1][end:]
            second = number
        else:                                                    # on a line of its own
            slash = lines[number - 1].rindex("/")
            lines[number - 1:number] = [lines[number - 1][:slash], "    " + copy + " /"]
            second = number + 1
        path = tmp_path / f"twice{n}.nml"
        path.write_text("\n".join(lines) + "\n")
        with pytest.raises(impact1d.InputError,
                           match=re.escape(f"twice{n}.nml:{second}: ") + f".*{name} is given twice "
                           rf"\(lines {number} and {second}\)"):
            impact1d.load_scene(path)


def quoted(text, rng):
    """text as a namelist string, in single or double quotes (the quote inside doubled)."""
    quote = rng.choice("'\"")
    return quote + text.replace(quote, quote * 2) + quote


def test_quoted_group_marks_and_separators_in_titles_are_text(tmp_path):
    rng = seeded("title")
    base = INPUT / "case3.nml"
    expected = scene_of(base)
    for n in range(N_FAMILY):
        title = "".join(rng.choice(TITLE_PIECES) for _ in range(rng.randint(1, 8)))
        text = base.read_text().replace("'Test case 3: conservation of energy'", quoted(title, rng))
        path = tmp_path / f"title{n}.nml"
        path.write_text(text)
        assert scene_of(path) == {**expected, "title": title.strip() or None}, title


def test_quoted_group_marks_and_separators_in_table_paths_are_text(tmp_path):
    rng = seeded("path")
    base = (INPUT / "case6.nml").read_text()
    reference = impact1d.simulate(impact1d.load_scene(INPUT / "case6.nml"), t_end=1.0)
    for n in range(N_FAMILY // 2):
        parts = ["".join(rng.choice(PATH_PIECES) for _ in range(rng.randint(1, 4))) for _ in range(2)]
        relative = Path(f"t{n}", *parts, "triangle.dat")
        (tmp_path / relative).parent.mkdir(parents=True)
        (tmp_path / relative).write_text((INPUT / "triangle.dat").read_text())
        path = tmp_path / f"path{n}.nml"
        path.write_text(base.replace("'triangle.dat'", quoted(str(relative), rng)))
        scene = impact1d.load_scene(path)
        assert scene.f1_table == str(tmp_path / relative)
        if n < 3:
            assert np.array_equal(impact1d.simulate(scene, t_end=1.0).x1, reference.x1)


def test_mutated_dat_lines_are_refused_naming_the_line_or_read_the_same(tmp_path):
    rng = seeded("dat")
    shutil.copy(INPUT / "triangle.dat", tmp_path / "triangle.dat")
    for n in range(N_FAMILY):
        source = rng.choice(sorted(INPUT.glob("input*.dat")))
        lines = source.read_text().splitlines()
        numbers = [i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")]
        i = rng.choice(numbers[:17])
        value = lines[i].split("#")[0].strip()
        path = tmp_path / f"dat{n}.dat"
        if rng.random() < 0.7:
            lines[i] = rng.choice(DAT_BAD)
            path.write_text("\n".join(lines) + "\n")
            with pytest.raises(impact1d.InputError, match=re.escape(f"dat{n}.dat:{i + 1}: ")):
                impact1d.load_scene(path)
        else:
            lines[i] = rng.choice(DAT_SAME).format(v=value)
            path.write_text("\n".join(lines) + "\n")
            assert scene_of(path) == {**scene_of(source), "f1_table": scene_of(path)["f1_table"]}, lines[i]
