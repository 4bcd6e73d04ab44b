"""What a new user ran into (issue: no lost results, no tracebacks, headline first), each checked
through the real command line: ``python -m bridge.scenario`` / ``python -m bridge.sweep`` in a
subprocess, as a user types them.  Every test here failed on the code before the fix it checks."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from bridge.config import SCENARIO_DIR
from bridge.sweep import plan_cases

REPO = Path(__file__).resolve().parents[2]


def cli(*args: str, module: str = "bridge.scenario", cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run the command as a user would; return the finished process (text output)."""
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True,
                          cwd=cwd or REPO, timeout=300)


def one_error_line(proc: subprocess.CompletedProcess, status: int = 2) -> str:
    """The run failed with ``status`` and said so in exactly one line, without a traceback."""
    assert proc.returncode == status, (proc.returncode, proc.stderr[-2000:])
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    return lines[0]


def strict_json(path: Path) -> dict:
    """Parse as a browser would: NaN, Infinity and -Infinity are not JSON."""
    def refuse(name):
        raise AssertionError(f"{path.name} holds {name}, which is not JSON")

    return json.loads(path.read_text(), parse_constant=refuse)


def copy_scenario(src: str, dst: Path, edit=None) -> Path:
    text = (SCENARIO_DIR / f"{src}.toml").read_text()
    dst.write_text(edit(text) if edit else text)
    return dst


# ------------------------------------------------------------------------------ results never lost
@pytest.mark.slow   # ~4 s (runs of the command): runs in CI with -m slow
def test_rerun_into_a_result_folder_is_refused_and_overwrite_keeps_the_users_files(tmp_path):
    out = str(tmp_path)
    # a run of more stages (cable and fem: the flutter stage would only add time) ...
    assert cli("great_belt", "--stages", "fem", "--quick", "--quiet", "--out", out).returncode == 0
    notes = tmp_path / "great_belt" / "my_notes.txt"
    notes.write_text("mine")
    full = strict_json(tmp_path / "great_belt" / "summary.json")
    assert "fem.frequency_S_T1_hz" in full

    line = one_error_line(cli("great_belt", "--stages", "cable", "--quick", "--out", out))
    assert "--overwrite" in line and "great_belt" in line
    assert strict_json(tmp_path / "great_belt" / "summary.json") == full  # the full results are untouched

    again = cli("great_belt", "--stages", "cable", "--quick", "--overwrite", "--out", out)
    assert again.returncode == 0, again.stderr
    assert notes.read_text() == "mine"  # a file the program did not write survives --overwrite
    summary = strict_json(tmp_path / "great_belt" / "summary.json")
    assert summary["stages"] == ["cable"]
    assert "my_notes.txt" not in summary["run.files"]
    # the earlier run's files are gone (replaced), not left beside the new ones
    assert not list((tmp_path / "great_belt").glob("fem_*.png"))


@pytest.mark.slow  # ~9 s of full pipeline runs: runs in CI with -m slow (default run under 2 min)
def test_a_users_file_named_like_an_output_is_never_overwritten(tmp_path):
    out = str(tmp_path)
    assert cli("great_belt", "--stages", "cable", "--quick", "--quiet", "--out", out).returncode == 0
    (tmp_path / "great_belt" / "fem_mode_S-V1.png").write_bytes(b"my own picture")
    line = one_error_line(cli("great_belt", "--stages", "fem", "--quick", "--quiet", "--overwrite", "--out", out))
    assert "fem_mode_S-V1.png" in line
    assert (tmp_path / "great_belt" / "fem_mode_S-V1.png").read_bytes() == b"my own picture"
    assert strict_json(tmp_path / "great_belt" / "summary.json")["stages"] == ["cable"]


def test_a_folder_whose_summary_is_not_ours_is_not_ours(tmp_path):
    """--overwrite trusts only a summary.json this program wrote (with scenario.name and stages): a folder
    of another tool's files named like ours is refused, its files untouched."""
    folder = tmp_path / "great_belt"
    folder.mkdir()
    (folder / "summary.json").write_text('{"score": 3}')
    (folder / "results.h5").write_bytes(b"another tool's file")
    line = one_error_line(cli("great_belt", "--stages", "cable", "--quick", "--quiet", "--overwrite",
                              "--out", str(tmp_path)))
    assert "not written by the program" in line
    assert (folder / "results.h5").read_bytes() == b"another tool's file"


def test_the_name_is_the_files_own_and_checked(tmp_path):
    mine = copy_scenario("great_belt", tmp_path / "mybridge.toml")
    proc = cli(str(mine), "--stages", "cable", "--quick", "--quiet", "--out", str(tmp_path / "out"))
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "out" / "mybridge" / "summary.json").is_file()
    assert not (tmp_path / "out" / "great_belt").exists()

    twin = tmp_path / "twin.toml"
    twin.write_text('name = "mybridge"\n' + mine.read_text())
    line = one_error_line(cli(str(mine), str(twin), "--stages", "cable", "--out", str(tmp_path / "out2")))
    assert "mybridge" in line and not (tmp_path / "out2").exists()

    for bad in ("../escaped", "", ".hidden", "a/b"):
        f = tmp_path / "bad.toml"
        f.write_text(f'name = "{bad}"\n' + mine.read_text())
        line = one_error_line(cli(str(f), "--stages", "cable", "--out", str(tmp_path / "out3")))
        assert line.startswith("error: name = ")
    assert not (tmp_path / "escaped").exists() and not (tmp_path / "out3").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_the_output_folder_is_checked_before_any_work(tmp_path):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    line = one_error_line(cli("great_belt", "--out", str(a_file)))
    assert "--out" in line and "file" in line
    # a folder nobody can write to (root ignores permission bits: /proc cannot hold a new folder)
    if os.geteuid() == 0:
        locked = Path("/proc/bridge-no-such-folder")
    else:
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o555)
    line = one_error_line(cli("great_belt", "--out", str(locked / "out")))
    assert "--out" in line and "cannot write" in line


@pytest.mark.slow   # ~4 s (runs of the command): runs in CI with -m slow
def test_every_output_file_gets_the_same_mode(tmp_path):
    proc = cli("great_belt", "model_c", "--stages", "cable", "--quick", "--quiet", "--out", str(tmp_path / "run"))
    assert proc.returncode == 0, proc.stderr
    proc = cli("great_belt", "--main-span", "1624,2000", "--stages", "cable", "--quick", "--workers", "1",
               "--out", str(tmp_path / "sweep"), module="bridge.sweep")
    assert proc.returncode == 0, proc.stderr
    files = [p for p in tmp_path.rglob("*") if p.is_file() and ".cache" not in p.parts]
    assert any(p.name == "comparison.md" for p in files) and any(p.name == "sweep.h5" for p in files)
    assert any(p.name == "sweep.csv" for p in files) and any(p.name == "sweep.png" for p in files)
    modes = {oct(p.stat().st_mode & 0o777) for p in files}
    assert len(modes) == 1, {p.relative_to(tmp_path).as_posix(): oct(p.stat().st_mode & 0o777) for p in files}


# ------------------------------------------------------------------------------ bad input: one line, exit 2
@pytest.mark.parametrize("key, line_pattern", [
    ("youngs_modulus_Pa = 2.1e11", "youngs_modulus_Pa = inf"),
    ("density_kg_m3 = 1.225", "density_kg_m3 = inf"),
    ("area_m2 = 0.41 ", "area_m2 = inf "),
])
def test_infinite_numbers_are_refused(tmp_path, key, line_pattern):
    f = copy_scenario("great_belt", tmp_path / "inf_case.toml", lambda t: t.replace(key, line_pattern, 1))
    assert line_pattern in f.read_text()
    line = one_error_line(cli(str(f), "--quick", "--out", str(tmp_path / "out")))
    assert "finite" in line and line_pattern.split("=")[0].strip() in line
    assert not (tmp_path / "out").exists()


def _numeric_leaves(node, prefix=""):
    """Dotted paths of every number in a TOML tree (lists of tables included)."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _numeric_leaves(v, f"{prefix}.{k}" if prefix else k)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _numeric_leaves(v, f"{prefix}[{i}]")
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        yield prefix


def _set(node, path, value):
    parts = re.findall(r"[^.\[\]]+|\[\d+\]", path)
    for part in parts[:-1]:
        node = node[int(part[1:-1])] if part.startswith("[") else node[part]
    last = parts[-1]
    if last.startswith("["):
        node[int(last[1:-1])] = value
    else:
        node[last] = value


@pytest.mark.parametrize("scenario", sorted(f.stem for f in SCENARIO_DIR.glob("*.toml")))
def test_every_number_of_every_shipped_scenario_refuses_inf_and_nan(tmp_path, scenario):
    """Every numeric key, set to inf, -inf or NaN, is an InputError naming that key (read in-process:
    the three command-line cases above show that an InputError is one line and exit 2)."""
    import copy
    import tomllib

    from bridge.config import load_scenario
    from bridge.errors import InputError

    data = tomllib.loads((SCENARIO_DIR / f"{scenario}.toml").read_text())
    paths = list(_numeric_leaves(data))
    assert paths or "reference" in data
    for path in paths:
        for bad in (float("inf"), -float("inf"), float("nan")):
            d = copy.deepcopy(data)
            _set(d, path, bad)
            f = tmp_path / f"{scenario}.toml"
            f.write_text(_toml(d))
            with pytest.raises(InputError) as err:
                load_scenario(f)
            assert err.value.key.split(".")[-1].split("[")[0] in path, (path, str(err.value))


def _toml(data, prefix=""):
    """A minimal TOML writer for the shipped scenarios' shapes (tables, inline tables, lists of tables)."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, float):
            return "nan" if v != v else ("inf" if v == float("inf") else "-inf" if v == -float("inf") else repr(v))
        if isinstance(v, int):
            return str(v)
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        if isinstance(v, list):
            return "[ " + ", ".join(value(x) for x in v) + " ]"
        raise TypeError(v)

    lines = [f"{k} = {value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, v in data.items():
        if isinstance(v, dict):
            name = f"{prefix}.{k}" if prefix else k
            lines += ["", f"[{name}]", _toml(v, name)]
    return "\n".join(lines)


@pytest.mark.parametrize("stages", ["", ",,,", " , "])
def test_an_empty_stage_list_is_an_error(tmp_path, stages):
    line = one_error_line(cli("great_belt", "--stages", stages, "--out", str(tmp_path / "out")))
    assert "--stages" in line
    assert not (tmp_path / "out").exists()


def test_summary_json_is_strict_json(tmp_path):
    """No flutter below the top speed: the missing numbers are null, the flag is false."""
    f = copy_scenario("great_belt_thesis_modes", tmp_path / "slow_wind.toml",
                      lambda t: t.replace("max_speed_m_s = 150.0", "max_speed_m_s = 20.0"))
    proc = cli(str(f), "--quiet", "--out", str(tmp_path / "out"))
    assert proc.returncode == 0, proc.stderr
    s = strict_json(tmp_path / "out" / "slow_wind" / "summary.json")
    assert s["flutter.critical_speed_m_s"] is None
    assert s["flutter.flutter"] is False
    assert not [k for k, v in s.items() if v == "none"]


def test_json_value_turns_every_missing_number_into_null_and_unwraps_numpy():
    """bridge.results.json_value, which the summary and the tools' JSON go through: NaN and infinities as null
    at any depth (a 0-d array's too), NumPy scalars and arrays as plain values."""
    import json

    import numpy as np

    from bridge.results import json_value

    v = json_value({"a": np.array(np.nan), "b": (np.array([1.5, np.inf]),), "c": {"d": [np.float32(2.0), np.nan]},
                    "e": np.bool_(True), "f": np.int64(3)})
    assert v == {"a": None, "b": [[1.5, None]], "c": {"d": [2.0, None]}, "e": True, "f": 3}
    assert type(v["f"]) is int and type(v["e"]) is bool
    json.dumps(v, allow_nan=False)


# ------------------------------------------------------------------------------ sweeps
@pytest.mark.slow  # ~11 s of full pipeline runs: runs in CI with -m slow (default run under 2 min)
def test_sweep_resumes_only_cases_run_with_the_same_stages(tmp_path):
    base = ["great_belt", "--main-span", "1624", "--quick", "--aerodynamics", "theodorsen", "--workers", "1",
            "--out", str(tmp_path)]
    assert cli(*base, "--stages", "cable", module="bridge.sweep").returncode == 0
    proc = cli(*base, "--stages", "fem", module="bridge.sweep")   # more stages than the finished case
    assert proc.returncode == 0, proc.stderr
    assert "skipped" not in proc.stderr and re.search(r": done: .*\(from the cache: cable\)", proc.stderr)
    (case,) = (tmp_path / "sweep_great_belt" / "cases").iterdir()
    assert "fem.frequency_S_T1_hz" in strict_json(case / "summary.json")
    # the same inputs and stages again
    assert "skipped" in cli(*base, "--stages", "fem", module="bridge.sweep").stderr


def test_sweep_refuses_cases_of_one_name_and_a_bad_sweep_name(tmp_path):
    base = ["great_belt", "--stages", "cable", "--quick", "--workers", "1", "--out", str(tmp_path)]
    line = one_error_line(cli(*base, "--main-span", "1624,1624", module="bridge.sweep"))
    assert "one name" in line
    line = one_error_line(cli(*base, "--main-span", "1624", "--name", "../outside", module="bridge.sweep"))
    assert line.startswith("error: --name")
    assert not list(tmp_path.iterdir())


def test_sweep_table_counts_only_cases_of_the_current_inputs(tmp_path):
    from bridge.sweep import collect

    cases = plan_cases("great_belt", [1624.0, 2000.0], {})
    for c, key in zip(cases, ["now", "earlier"], strict=True):
        (tmp_path / "cases" / c.name).mkdir(parents=True)
        (tmp_path / "cases" / c.name / "summary.json").write_text(json.dumps(
            {"scenario.main_span_m": c.main_span_m, "cable.area_m2": 0.41, "run.key": key}))
    collect(cases, tmp_path / "cases", tmp_path, None, keys={c.name: "now" for c in cases})
    import h5py

    with h5py.File(tmp_path / "sweep.h5") as h5:
        assert h5["finished"][:].tolist() == [True, False]


def test_sweep_checks_stages_and_plot_key_before_running(tmp_path):
    base = ["great_belt", "--main-span", "1624,2000", "--quick", "--workers", "1", "--out", str(tmp_path)]
    line = one_error_line(cli(*base, "--stages", "bogus", module="bridge.sweep"))
    assert "bogus" in line
    line = one_error_line(cli(*base, "--stages", "cable", "--plot", "no.such.key", module="bridge.sweep"))
    assert "no.such.key" in line
    assert not list(tmp_path.iterdir())
    # a key of a stage that runs but that no case produced: refused before sweep.h5 is written
    proc = cli(*base, "--stages", "cable", "--plot", "cable.no_such_number", module="bridge.sweep")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    line = proc.stderr.strip().splitlines()[-1]
    assert "cable.no_such_number" in line and "available" in line
    assert not (tmp_path / "sweep_great_belt" / "sweep.h5").exists()


# ------------------------------------------------------------------------------ Ctrl-C
@pytest.mark.parametrize("module, args", [
    ("bridge.scenario", ["great_belt", "model_a", "model_b"]),
    pytest.param("bridge.sweep", ["great_belt", "--main-span", "1624,2000,3000", "--workers", "2",
                                  "--aerodynamics", "theodorsen"],
                 marks=pytest.mark.slow),   # ~18 s: runs in CI with -m slow
])
def test_ctrl_c_is_one_line_and_exit_130(tmp_path, module, args):
    """Interrupt at several moments (loading, cable, FEM, writing): never a traceback.

    The clock starts when the command's own code runs (``bridge.interrupts`` imported, seen through
    ``-X importtime``), not at process start: an interrupt inside the interpreter's own start-up (its
    ``site`` import, before any line of this project runs) ends in CPython's "Fatal Python error",
    which no program can prevent; under load that start-up alone takes longer than the first delay.
    """
    seen = 0
    for delay in (0.05, 0.3, 1.0, 2.0, 3.5):
        out = tmp_path / f"d{delay}"
        proc = subprocess.Popen([sys.executable, "-X", "importtime", "-m", module, *args, "--out", str(out)],
                                cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        lines: list[str] = []
        for line in proc.stderr:  # until the project's interrupt handling is loaded
            lines.append(line)
            if line.rstrip().endswith("bridge.interrupts"):
                break
        reader = threading.Thread(target=lines.extend, args=(proc.stderr,), daemon=True)
        reader.start()  # keep draining: a full pipe would stall the command
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        sent = time.monotonic()
        proc.wait(timeout=120)
        # promptly: a sweep used to run the cases already queued to its workers to the end (40 s here)
        assert time.monotonic() - sent < 15, (delay, time.monotonic() - sent)
        reader.join(timeout=30)
        assert not reader.is_alive(), "a process of the command still holds its stderr open after it exited"
        if proc.returncode == 0:
            continue  # finished before the interrupt: nothing to check at this delay
        seen += 1
        stderr = "".join(line for line in lines if not line.startswith("import time:"))
        assert proc.returncode == 130, (delay, stderr[-3000:])
        assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr[-3000:]
        assert stderr.strip().splitlines()[-1].startswith("interrupted"), stderr[-500:]
        # nothing half-done: no temporary result folders
        assert not [p for p in out.rglob(".*.tmp")] if out.exists() else True
    assert seen >= 2


# ------------------------------------------------------------------------------ stage cache
@pytest.mark.slow  # ~17 s (five runs of the pipeline): runs in CI with -m slow; the keys are checked below
def test_stage_cache_reuses_unchanged_stages_only(tmp_path):
    out = str(tmp_path / "out")
    theodorsen = ("--aerodynamics", "theodorsen")   # the cache of the stages, not the CFD's, is checked here
    first = cli("great_belt", "--quick", *theodorsen, "--out", out)
    assert first.returncode == 0 and "reusing" not in first.stderr
    vc = strict_json(tmp_path / "out" / "great_belt" / "summary.json")["flutter.critical_speed_m_s"]
    proc = cli("great_belt", "--stages", "flutter", "--quick", *theodorsen, "--overwrite", "--out", out)
    assert proc.returncode == 0, proc.stderr
    for stage in ("cable", "fem", "flutter"):
        assert re.search(rf"{stage}: inputs unchanged, reusing", proc.stderr), proc.stderr
    # the reused results are the same numbers
    assert strict_json(tmp_path / "out" / "great_belt" / "summary.json")["flutter.critical_speed_m_s"] == vc

    # a flutter option changed: cable and fem reused, flutter recomputed
    f = copy_scenario("great_belt", tmp_path / "great_belt.toml",
                      lambda t: t.replace('aerodynamics = "cfd"\n',
                                          'aerodynamics = "cfd"\nmax_speed_m_s = 140.0\nmultimode = false\n', 1))
    proc = cli(str(f), "--quick", *theodorsen, "--overwrite", "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "cable: inputs unchanged" in proc.stderr and "fem: inputs unchanged" in proc.stderr
    assert "flutter: inputs unchanged" not in proc.stderr
    # a structural input changed: everything downstream of it recomputed
    g = copy_scenario("great_belt", tmp_path / "great_belt.toml",
                      lambda t: t.replace("mass_per_length_kg_m = 14.78e3", "mass_per_length_kg_m = 15.0e3"))
    assert "15.0e3" in g.read_text()
    proc = cli(str(g), "--stages", "fem", "--quick", "--overwrite", "--out", out)
    assert proc.returncode == 0 and "inputs unchanged" not in proc.stderr, proc.stderr
    # --no-cache recomputes everything
    proc = cli("great_belt", "--stages", "fem", "--quick", "--overwrite", "--no-cache", "--out", out)
    assert proc.returncode == 0 and "inputs unchanged" not in proc.stderr, proc.stderr


def test_stage_key_follows_code_inputs_upstream_and_input_files(tmp_path):
    from dataclasses import replace

    from bridge.cache import stage_key
    from bridge.config import load_scenario
    from bridge.flutter.options import FlutterOptions

    sc = load_scenario("great_belt")
    k = stage_key("flutter", sc, {"fem": "a"}, quick=False)
    assert k == stage_key("flutter", sc, {"fem": "a"}, quick=False)
    assert k != stage_key("flutter", sc, {"fem": "b"}, quick=False)   # upstream output differs
    assert k != stage_key("flutter", sc, {"fem": "a"}, quick=True)
    assert stage_key("cable", sc, {}, False) == stage_key("cable", replace(sc, flutter=FlutterOptions()), {}, False)
    # every kind of input is in the key: arrays of given modes, flags, sequences of numbers
    import numpy as np

    from bridge.aero.options import AeroOptions

    modal = load_scenario("great_belt_thesis_modes")
    stiffer = replace(modal, modal=replace(modal.modal, frequencies_hz=np.array([0.128, 0.35])))
    assert stage_key("flutter", modal, {}, False) != stage_key("flutter", stiffer, {}, False)
    no_pk = replace(modal, flutter=replace(modal.flutter, multimode=False))
    assert stage_key("flutter", modal, {}, False) != stage_key("flutter", no_pk, {}, False)
    a, b = replace(sc, aero=AeroOptions()), replace(sc, aero=AeroOptions(reduced_velocities=(5.0, 9.0)))
    assert stage_key("aero", a, {}, False) != stage_key("aero", b, {}, False)
    # the bytes of a file the scenario names are part of the key
    csv = tmp_path / "derivatives.csv"
    csv.write_text("K,H1\n1,2\n")
    with_file = replace(sc, source_path=str(tmp_path / "s.toml"),
                        flutter=FlutterOptions(aerodynamics="derivatives", derivatives_path="derivatives.csv"))
    k1 = stage_key("flutter", with_file, {}, False)
    csv.write_text("K,H1\n1,3\n")
    assert stage_key("flutter", with_file, {}, False) != k1


def test_a_shared_stage_is_one_result_for_scenarios_of_other_names(monkeypatch):
    """A stage declared ``shared`` (a deck's aerodynamics) leaves the name out of its key, so two bridges
    with the same inputs share it; the name-bearing stages of today do not."""
    from dataclasses import replace

    from bridge import stages
    from bridge.cache import stage_key
    from bridge.config import load_scenario

    a = load_scenario("great_belt")
    b = replace(a, name="another_bridge", description="a copy", source_path="/elsewhere/x.toml")
    assert stage_key("cable", a, {}, False) != stage_key("cable", b, {}, False)
    monkeypatch.setitem(stages.STAGES, "cable", replace(stages.STAGES["cable"], shared=True))
    assert stage_key("cable", a, {}, False) == stage_key("cable", b, {}, False)
    c = replace(b, girder=replace(b.girder, width_m=30.0))
    assert stage_key("cable", a, {}, False) != stage_key("cable", c, {}, False)


# ------------------------------------------------------------------------------ what a user reads
@pytest.mark.slow  # ~15 s of full pipeline runs: runs in CI with -m slow (default run under 2 min)
def test_headline_on_the_terminal_and_atop_the_report(tmp_path):
    proc = cli("great_belt", "thin_plate_section", "--quick", "--aerodynamics", "theodorsen", "--out", str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    for name, pair in (("great_belt", "S-V1+S-T1"), ("thin_plate_section", "heave+pitch")):
        block = proc.stdout.split(f"{name}: results in")[1]
        assert re.search(r"flutter speed V_c = \d+\.\d m/s at f = 0\.\d+ Hz", block)
        assert f"governing modes {pair}" in block and "multimode p-k V_c" in block and "divergence" in block
        assert re.search(r"theodorsen[^,)]* aerodynamics", block)
        report = (tmp_path / name / "report.md").read_text().splitlines()
        assert report[2].startswith("**Flutter speed V_c = "), report[:4]
    assert "with the lateral modes: multimode p-k V_c" in proc.stdout.split("thin_plate_section: results in")[0]
    table = (tmp_path / "comparison.md").read_text()
    for row in ("governing mode pair", "multimode p-k V_c", "static divergence speed"):
        assert row in table


@pytest.mark.slow  # ~6 s of full pipeline runs: runs in CI with -m slow (default run under 2 min)
def test_no_cuda_warning_on_a_cpu_run(tmp_path):
    proc = cli("great_belt", "--stages", "fem", "--quick", "--out", str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert "CUDA" not in proc.stderr


def test_version_and_help_list_scenarios_and_exit_codes():
    from bridge import __version__

    assert cli("--version").stdout.strip() == f"bridge-flutter {__version__}"
    text = cli("--help").stdout
    for f in SCENARIO_DIR.glob("*.toml"):
        assert f.stem in text
    for code in ("0", "2", "3", "130"):
        assert re.search(rf"^\s+{code}\s", text, re.M), code


def test_readme_commands_and_option_names_match_the_code():
    readme = (REPO / "README.md").read_text()
    from bridge.flutter.options import AERODYNAMIC_MODELS

    assert "Scanlan\nflutter-derivative" not in readme and "Scanlan flutter-derivative" not in readme
    for model in AERODYNAMIC_MODELS:
        assert f"`{model}`" in readme, model
    from bridge import scenario, sweep

    parsers = (scenario.build_parser(), sweep.build_parser())
    known = {o for parser in parsers for a in parser._actions for o in a.option_strings}
    for flag in set(re.findall(r"(?<![\w-])--[a-z][a-z-]+", readme)):
        assert flag in known, f"README names an option the commands do not have: {flag}"


def test_an_interrupt_swallowed_by_a_destructor_is_delivered_again(capfd):
    """Ctrl-C can land inside a destructor or weakref callback, where Python prints "Exception ignored"
    and carries on (seen once in a sweep): the command must still stop, and print nothing of it."""
    from bridge.interrupts import Interrupts

    class Interrupted:
        def __del__(self):
            raise KeyboardInterrupt

    with Interrupts() as interrupts, pytest.raises(KeyboardInterrupt):
        Interrupted()          # the destructor's interrupt is swallowed by Python ...
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline:  # ... and must reach the main flow again, here
            time.sleep(0.001)
    assert interrupts.fired
    assert "Exception ignored" not in capfd.readouterr().err
