"""The stage cache holds data only (bridge.cache, bridge.datastore): a result folder, with its cache, travels
between people, so nothing a file in it says may run as code.  A crafted pickle or an entry naming a type that is
not data is never acted on: the run says so in one line, computes the stage again and replaces the entry; every
stage's result reads back equal to what was computed.  Every test here failed on the pickle cache before."""

from __future__ import annotations

import dataclasses
import io
import json
import math
import pickle
import subprocess
import sys
import types
from pathlib import Path
from typing import NamedTuple

import h5py
import numpy as np
import pytest
import scipy.sparse as sp

REPO = Path(__file__).resolve().parents[2]


def cli(*args: str) -> subprocess.CompletedProcess:
    """Run ``python -m bridge.scenario`` as a user would; return the finished process (text output)."""
    return subprocess.run([sys.executable, "-m", "bridge.scenario", *args], capture_output=True, text=True,
                          cwd=REPO, timeout=300)


def fortran(a: np.ndarray) -> bool:
    """An array laid out in Fortran order (a strided view reads back as a plain array: no layout to keep)."""
    return a.ndim > 1 and a.flags.f_contiguous and not a.flags.c_contiguous


def same(a, b, path: str = "data") -> None:
    """``b`` equals ``a`` all the way down: types, dtypes, shapes, values (NaN equal to NaN, the sign of
    zero kept), array flags (read-only, Fortran order), the fields of dataclasses and the attributes of any
    other object."""
    assert type(a) is type(b), f"{path}: {type(a).__name__} read back as {type(b).__name__}"
    if isinstance(a, np.ndarray):
        assert (a.dtype, a.shape) == (b.dtype, b.shape), f"{path}: {a.dtype}{a.shape} vs {b.dtype}{b.shape}"
        assert np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"), path
        assert a.flags.writeable == b.flags.writeable and fortran(a) == fortran(b), path
    elif isinstance(a, np.generic):
        assert a.dtype == b.dtype and (a == b or (a != a and b != b)), path
    elif type(a) is float:
        assert a == b and math.copysign(1, a) == math.copysign(1, b) or (math.isnan(a) and math.isnan(b)), path
    elif a is None or type(a) in (bool, int, str, bytes, complex):
        assert a == b, path
    elif isinstance(a, (types.FunctionType, types.BuiltinFunctionType, type)):
        assert a is b, path
    elif sp.issparse(a):
        assert (a.format, a.shape) == (b.format, b.shape), path
        for part in ("data", "indices", "indptr", "row", "col"):
            if hasattr(a, part):
                same(getattr(a, part), getattr(b, part), f"{path}.{part}")
    elif isinstance(a, dict):
        assert list(a) == list(b), path
        for k in a:
            same(a[k], b[k], f"{path}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"{path}[{i}]")
    else:
        if dataclasses.is_dataclass(a):
            for f in dataclasses.fields(a):
                same(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
        assert set(vars(a)) == set(vars(b)), f"{path}: attributes {set(vars(a)) ^ set(vars(b))}"
        for k in vars(a):
            same(vars(a)[k], vars(b)[k], f"{path}.{k}")


def round_trip(obj):
    """``obj`` written by bridge.datastore into an HDF5 file in memory and read back."""
    from bridge import datastore

    buf = io.BytesIO()
    with h5py.File(buf, "w") as h5:
        datastore.write(h5.create_group("d"), obj)
    with h5py.File(buf, "r") as h5:
        return datastore.read(h5["d"])


def bridge_scenario():
    """The Great Belt with Theodorsen's aerodynamics: cable, fem and flutter run in seconds (no CFD)."""
    from bridge.config import load_scenario
    from bridge.flutter.options import FlutterOptions

    sc = load_scenario("great_belt")
    return dataclasses.replace(sc, flutter=dataclasses.replace(sc.flutter or FlutterOptions(),
                                                               aerodynamics="theodorsen"))


@pytest.fixture(scope="module")
def stage_outputs():
    """cable, fem and flutter of the Great Belt, quick (about 3 s), and the scenario."""
    from bridge.pipeline import run_stages
    from bridge.stages import RunOptions

    sc = bridge_scenario()
    return sc, run_stages(sc, ["flutter"], RunOptions(quick=True))


def stored(out):
    """``out`` as the cache keeps it, its figures stood in for by a few bytes each (rendering them takes
    seconds and their PNG bytes are stored as they are)."""
    from bridge import cache

    return cache.store(dataclasses.replace(out, figures={f: f"PNG {f}".encode() for f in out.figures}))


def cable_entry(out: Path) -> Path:
    """The entry folder of the cable stage of ``great_belt --stages cable --quick`` in ``out/.cache``."""
    from bridge.config import load_scenario
    from bridge.pipeline import stage_keys
    from bridge.stages import RunOptions

    key = stage_keys(load_scenario("great_belt"), ["cable"], RunOptions(quick=True))["cable"]
    return out / ".cache" / "cable" / key


def reused(out: Path) -> bool:
    """The cable entry in ``out`` reads back as a whole stored result (what a second run reuses)."""
    from bridge import cache

    entry = cable_entry(out)
    hit = cache.load(out / ".cache", "cable", entry.name)
    return hit is not None and hit.from_cache and hit.data is not None


class _Touch:
    """Pickled, a call of ``open(path, "w")``: unpickling it creates the file (any call would do)."""

    def __init__(self, path: Path):
        self.path = str(path)

    def __reduce__(self):
        return (open, (self.path, "w"))


# ------------------------------------------------------------------------------ crafted entries are never run
def test_a_crafted_pickle_in_an_entry_folder_is_never_read_and_the_entry_is_replaced(tmp_path):
    bait = tmp_path / "bait"
    pickle.loads(pickle.dumps(_Touch(bait)))   # the payload is live: unpickling it does create a file
    assert bait.exists()
    marker = tmp_path / "pwned"
    entry = cable_entry(tmp_path / "out")
    entry.mkdir(parents=True)
    (entry / "output.pkl").write_bytes(pickle.dumps(_Touch(marker)))

    proc = cli("great_belt", "--stages", "cable", "--quick", "--out", str(tmp_path / "out"))
    assert proc.returncode == 0, proc.stderr
    assert not marker.exists()
    warned = [ln for ln in proc.stderr.splitlines() if str(entry) in ln]
    assert len(warned) == 1 and "not readable as this stage's data" in warned[0], proc.stderr
    assert "computing it again" in warned[0] and "Traceback" not in proc.stderr
    assert not (entry / "output.pkl").exists() and (entry / "entry.h5").is_file()
    assert reused(tmp_path / "out")   # replaced by a good entry, which the next run takes


def test_an_entry_naming_a_type_that_is_not_data_is_refused_in_one_line_and_replaced(tmp_path):
    from bridge import cache
    from bridge.stages import StageOutput

    out = tmp_path / "out"   # a well-made entry at the cable's key, whose data is then changed
    cache.save(out / ".cache", "cable", cable_entry(out).name,
               StageOutput(summary={}, write_h5=lambda g: None, report="", data={"x": 1}))
    f = cable_entry(out) / "entry.h5"
    assert f.is_file() and not list(cable_entry(out).glob("*.pkl"))
    marker = tmp_path / "pwned"
    with h5py.File(f, "r+") as h5:   # the data now names os.system with a command
        del h5["data/tree"]
        h5["data/tree"] = json.dumps({"$": "object", "type": "os:system", "arguments": {"command": f"touch {marker}"}})

    proc = cli("great_belt", "--stages", "cable", "--quick", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    assert not marker.exists()
    warned = [ln for ln in proc.stderr.splitlines() if str(f) in ln]
    assert len(warned) == 1, proc.stderr
    assert "cable: the stored result in" in warned[0] and "'os:system' is not a class of bridge" in warned[0]
    assert len([ln for ln in proc.stderr.splitlines() if "not readable" in ln]) == 1
    assert reused(out)


def test_a_result_the_cache_cannot_hold_is_computed_and_not_kept(tmp_path, monkeypatch):
    import bridge.cable_stage
    from bridge.config import load_scenario
    from bridge.pipeline import run_stages
    from bridge.stages import RunOptions, StageOutput

    def run(scenario, upstream, options):
        return StageOutput(summary={}, write_h5=lambda g: None, report="## cable\n", data=lambda: None)

    monkeypatch.setattr(bridge.cable_stage, "run", run)
    said: list[str] = []
    outs = run_stages(load_scenario("great_belt"), ["cable"],
                      RunOptions(quick=True, cache=tmp_path, progress=said.append))
    assert callable(outs["cable"].data)
    assert [m for m in said if "not kept in the stage cache" in m and "function" in m], said
    assert not list(tmp_path.rglob("entry.h5")) and not list(tmp_path.rglob("*.tmp"))


# ------------------------------------------------------------------------------ every stage's data reads back
def test_every_stage_reads_back_from_the_cache_as_it_was_computed(stage_outputs, tmp_path):
    import bridge.cache
    import bridge.datastore
    from bridge import cache

    for module in (bridge.cache, bridge.datastore):
        assert "import pickle" not in Path(module.__file__).read_text()
    _, outs = stage_outputs
    assert list(outs) == ["cable", "fem", "flutter"]
    for name, computed in outs.items():
        same(computed.data, round_trip(computed.data), name)
        out = stored(computed)
        cache.save(tmp_path, name, "k" * 64, out)
        entry = tmp_path / name / ("k" * 64)
        assert [p.name for p in entry.iterdir()] == ["entry.h5"] and h5py.is_hdf5(entry / "entry.h5")
        back = cache.load(tmp_path, name, "k" * 64)
        assert back.from_cache and back.summary == out.summary and back.report == out.report
        assert list(back.figures) == list(out.figures) and back.figures == out.figures
        assert back.write_h5.image == out.write_h5.image
        same(out.data, back.data, name)
    # the kinds of data the stages hold include sparse matrices and read-only arrays
    assert sp.issparse(outs["fem"].data.assembled.stiffness_elastic)
    assert not outs["flutter"].data.modal_model.frequencies_hz.flags.writeable


def test_the_flutter_stage_on_the_stored_fem_result_gives_the_same_answer(stage_outputs, tmp_path):
    from bridge import cache
    from bridge.stages import RunOptions, resolve_stage

    sc, outs = stage_outputs
    cache.save(tmp_path, "fem", "f" * 64, stored(outs["fem"]))
    assert [p.name for p in (tmp_path / "fem" / ("f" * 64)).iterdir()] == ["entry.h5"]
    fem = cache.load(tmp_path, "fem", "f" * 64)
    again = resolve_stage("flutter")(sc, {"cable": outs["cable"], "fem": fem}, RunOptions(quick=True))
    assert again.summary == outs["flutter"].summary
    same(outs["flutter"].data, again.data, "flutter")


def small_aero_result():
    """An AeroResult as the aero stage makes it (a named derivative table completed by the lateral terms of
    static coefficients), over made-up numbers: no CFD."""
    from bridge.aero.stage import AeroResult
    from bridge.aero.static import StaticCoefficients
    from bridge.flutter.aerodynamics import WithLateral
    from bridge.flutter.derivatives import FRF, derivatives_from_frf

    K = np.array([0.4, 0.6, 0.8, 1.2, 1.6])
    frf = FRF(h_pu=-1j * K * 6.0 + 0.1 * K**2, h_ptheta=6.1 + 0.5j * K, h_mu=-1.5j * K, h_mtheta=1.5 - 0.2j * K,
              h_qu=0.1j * K, h_qtheta=0.02 + 0j * K)
    table_cls = __import__("bridge.flutter.tables", fromlist=["DerivativeTable"]).DerivativeTable
    table = table_cls(K, derivatives_from_frf(K, frf), source="cfd (test)",
                      provides=("h_pu", "h_ptheta", "h_mu", "h_mtheta", "h_qu", "h_qtheta"))
    table.name = "cfd (test, tiny, Re 1e5)"
    angles = np.array([-2.0, 0.0, 2.0])
    static = StaticCoefficients(angles, np.array([0.09, 0.08, 0.09]), np.array([-0.2, 0.0, 0.21]),
                                np.array([-0.05, 0.0, 0.05]), np.zeros(3), np.array([np.nan, 0.2, np.nan]),
                                np.zeros((3, 3)), 0.14, (5.0, 10.0))
    records = ({"dof": "heave", "K": 0.4, "steps": 10, "wall_s": 1.5, "resumed_from_step": None, "Ks": [0.4, 0.8]},)
    return AeroResult("box", "tiny", 1.0e5, 1234, K, frf, frf._replace(h_pu=np.abs(frf.h_pu)),
                      WithLateral(table, static.quasi_steady()), records, "", static,
                      ({"angle_deg": 0.0, "lift": np.zeros(4)},))


def test_the_aero_result_and_the_aerodynamic_tables_read_back_as_they_were():
    from bridge.flutter.derivatives import FRF, VERTICAL_TORSIONAL
    from bridge.flutter.tables import DerivativeTable, FRFTable

    aero = small_aero_result()
    back = round_trip(aero)
    same(aero, back, "aero")
    omega = np.linspace(0.45, 1.5, 7)
    for x, y in zip(aero.model.frf(omega, 30.0), back.model.frf(omega, 30.0), strict=True):
        np.testing.assert_array_equal(x, y)
    # a 3-row derivative table (linear interpolation), and an FRF table over (Omega, V)
    short = DerivativeTable(aero.reduced_frequency[:3], aero.model.base.derivatives._replace(
        **{n: v[:3] for n, v in aero.model.base.derivatives._asdict().items()}), provides=aero.model.base.provides)
    same(short, round_trip(short), "short")
    om, v = np.array([0.1, 0.5, 1.0]), np.array([10.0, 60.0])
    grid = FRF(**{n: (1 + 2j) * np.outer(om, v) + k for k, n in enumerate(VERTICAL_TORSIONAL)}, h_qu=0.5j)
    table = FRFTable(om, v, grid, source="cfd", provides=VERTICAL_TORSIONAL + ("h_qu",))
    same(table, round_trip(table), "table")


def test_the_aero_result_keeps_the_grid_studys_change_of_each_derivative(tmp_path):
    """A run that a grid study covers carries the study's record: it reads back from the cache as it was, and
    results.h5:/aero/grid_study and the report give each derivative's change to the study's finest grid."""
    from dataclasses import replace

    from bridge.aero.accuracy import GridRecord
    from bridge.aero.stage import aero_report, write_aero_h5

    record = GridRecord("quick", (1.0, 2.0), "words", "how", 32, (8.0, 20.0),
                        (("H1", (0.02, -0.01)), ("A2", (0.05, -1.5))))
    aero = replace(small_aero_result(), grid_record=record)
    same(aero, round_trip(aero), "aero")
    aero = replace(aero, records=({**aero.records[0], "periods": 2},))   # as the stage's runs record them
    with h5py.File(tmp_path / "r.h5", "w") as h5:
        write_aero_h5(h5.create_group("aero"), aero)
    with h5py.File(tmp_path / "r.h5", "r") as h5:
        g = h5["aero/grid_study"]
        assert g.attrs["finest_cells_per_chord"] == 32 and g.attrs["basis"] == "how"
        np.testing.assert_array_equal(g["reduced_velocity"][:], [8.0, 20.0])
        np.testing.assert_array_equal(g["A2"][:], [0.05, -1.5])
        assert set(g) == {"reduced_velocity", "H1", "A2"} and g["H1"].attrs["unit"] == "1"
    text = aero_report(aero)
    assert "| U/(fB) | H1* | A2* |" in text and "| 20 | -1 % | sign turns |" in text, text
    with h5py.File(tmp_path / "none.h5", "w") as h5:   # no record (or one without a table): no group
        write_aero_h5(h5.create_group("aero"), small_aero_result())
        assert "grid_study" not in h5["aero"]


@pytest.mark.slow  # ~90 s: the aero stage's CFD on the "tiny" preset (one process)
def test_the_real_aero_stage_result_reads_back_as_it_was(tmp_path):
    from bridge import cache
    from bridge.config import load_scenario
    from bridge.pipeline import run_stages
    from bridge.stages import RunOptions

    out = run_stages(load_scenario("great_belt"), ["aero"], RunOptions(quick=True, quality="tiny", workers=1))["aero"]
    cache.save(tmp_path, "aero", "a" * 64, out)
    back = cache.load(tmp_path, "aero", "a" * 64)
    same(out.data, back.data, "aero")
    assert back.summary == out.summary


# ------------------------------------------------------------------------------ the codec itself
@dataclasses.dataclass(frozen=True)
class _Foreign:   # a dataclass outside bridge: never data
    x: int = 1


def test_the_codec_keeps_every_kind_of_value_exactly():
    from bridge.flutter.derivatives import FRF
    from bridge.stages import RunOptions

    shared = np.arange(6.0).reshape(2, 3)
    ro = np.linspace(0, 1, 4)
    ro.setflags(write=False)
    value = {
        "numbers": [None, True, False, 0, -7, 2**70, 1.5, -0.0, math.inf, -math.inf, math.nan, 1 + 2j,
                    "text é\u2603", b"\x00b"],
        (1, "a", 2.5): "tuple key", 3: "int key", 0.25: "float key",
        "scalars": (np.float64(0.1), np.float32(1 / 3), np.int32(-4), np.uint64(2**64 - 1), np.bool_(True),
                    np.complex64(1 - 1j), np.float16(0.5)),
        "arrays": [np.zeros((0, 3)), np.array(5.0), np.array([True, False]), np.array(["ab", "c"]),
                   np.array([b"x", b"yz"]), np.asfortranarray(np.arange(12.0).reshape(3, 4)), ro,
                   np.arange(5, dtype=np.int8), np.array([1 + 1j, np.nan])],
        "same": (shared, shared),
        "sparse": [sp.random(6, 5, density=0.4, format=f, random_state=1) for f in ("csr", "csc", "coo", "bsr")]
                  + [sp.csr_array(np.eye(3))],
        "classes": [FRF(np.ones(2), 2.0, 3j, 4.0), RunOptions(quick=True, quality="tiny")],
    }
    back = round_trip(value)
    same(value, back)
    assert back["same"][0] is back["same"][1]


@pytest.mark.parametrize("obj, reason", [
    (lambda: None, "function"),
    (Path("/tmp"), "not a class of bridge"),
    (_Foreign(), "not a class of bridge"),
    (__import__("bridge.cache", fromlist=["StoredGroup"]).StoredGroup(b""), "neither a dataclass"),
    (np.array([object()]), "dtype object"),
    (sp.lil_matrix((2, 2)), "lil_matrix"),
])
def test_the_codec_refuses_to_write_what_is_not_data(obj, reason):
    from bridge.datastore import DataError

    with pytest.raises(DataError, match=reason):
        round_trip({"x": [obj]})
    loop: list = []
    loop.append(loop)
    with pytest.raises(DataError, match="contains itself"):
        round_trip(loop)


def crafted(tree, arrays=None) -> h5py.Group:
    """A data group holding ``tree`` (JSON) and, in ``arrays``, what a function puts there."""
    h5 = h5py.File(io.BytesIO(), "w")
    g = h5.create_group("d")
    g.attrs["datastore"] = "1"
    g["tree"] = json.dumps(tree)
    a = g.create_group("arrays")
    if arrays:
        arrays(a)
    return g


SYSTEM = {"command": "touch /tmp/pwned-by-cache"}


@pytest.mark.parametrize("tree, arrays, reason", [
    ({"$": "object", "type": "os:system", "arguments": SYSTEM}, None, "not a class of bridge"),
    ({"$": "object", "type": "posix:system", "arguments": SYSTEM}, None, "not a class of bridge"),
    ({"$": "object", "type": "builtins:eval", "arguments": {"source": "1"}}, None, "not a class of bridge"),
    ({"$": "dataclass", "type": "subprocess:Popen", "fields": {"args": ["true"]}}, None, "not a class of bridge"),
    ({"$": "namedtuple", "type": "bridgex.y:Z", "fields": {}}, None, "not a class of bridge"),
    ({"$": "dataclass", "type": "bridge:InputError", "fields": {}}, None, "not a class of bridge"),
    ({"$": "dataclass", "type": "bridge.__main__:X", "fields": {}}, None, "not a class of bridge"),
    ({"$": "object", "type": "bridge.cache:os.system", "arguments": SYSTEM}, None, "not a class defined there"),
    ({"$": "dataclass", "type": "bridge.flutter.tables:Path", "fields": {}}, None, "not a class defined there"),
    ({"$": "object", "type": "bridge.flutter.tables:DerivativeTable.__init__.__globals__", "arguments": {}}, None,
     "not a class defined there"),
    ({"$": "dataclass", "type": "bridge.nowhere:X", "fields": {}}, None, "no module"),
    ({"$": "dataclass", "type": "bridge.toml_table:Table", "fields": {}}, None, "is not a dataclass"),
    ({"$": "object", "type": "bridge.cache:StoredGroup", "arguments": {"image": ""}}, None, "does not rebuild"),
    ({"$": "object", "type": "bridge.flutter.derivatives:FRF", "arguments": {}}, None, "does not rebuild"),
    ({"$": "namedtuple", "type": "bridge.stages:RunOptions", "fields": {}}, None, "is not a NamedTuple"),
    ({"$": "dataclass", "type": "bridge.stages:RunOptions", "fields": {"quick": True}}, None, "lacks the field"),
    ({"$": "dataclass", "type": "bridge.stages:RunOptions",
      "fields": {"quick": True, "progress": None, "cache": None, "quality": None, "workers": None,
                     "scheduler": None, "evil": 1}},
     None, "has no field evil"),
    ({"$": "object", "type": "bridge.flutter.tables:DerivativeTable", "arguments": {"K": "x", "derivatives": 1}},
     None, "refused its arguments"),
    ({"$": "eval", "source": "1"}, None, "unknown node kind"),
    ([1, 2], None, "wrong node kind"),
    ({"$": "list", "items": [{"no": "kind"}]}, None, "wrong node kind"),
    ({"$": "dict", "items": [[{"$": "list", "items": []}, 1]]}, None, "cannot be a key"),
    ({"$": "scalar", "dtype": "O", "value": 1}, None, "dtype 'O'"),
    ({"$": "sparse", "class": "lil_matrix", "shape": [2, 2]}, None, "sparse class"),
    ({"$": "array", "ref": "0"}, lambda a: a.create_group("0"), "expected a Dataset"),
    ({"$": "array", "ref": "0"}, lambda a: a.create_dataset("0", data=["a", "b"], dtype=h5py.string_dtype()),
     "dtype '|O'"),
    ({"$": "array", "ref": "0"}, lambda a: a.__setitem__("0", h5py.SoftLink("/d/tree")), "SoftLink"),
    ({"$": "array", "ref": "0"}, lambda a: a.__setitem__("0", h5py.ExternalLink("/etc/passwd", "/")),
     "ExternalLink"),
    ({"$": "array", "ref": "1"}, None, "missing"),
])
def test_the_codec_refuses_every_node_that_is_not_data(tree, arrays, reason):
    from bridge.datastore import DataError, read

    g = crafted(tree, arrays)
    try:
        with pytest.raises(DataError, match=reason) as err:
            read(g)
        assert "\n" not in str(err.value)
    finally:
        g.file.close()


class _Pair(NamedTuple):   # a NamedTuple outside bridge
    a: int
    b: int


def test_a_namedtuple_outside_bridge_is_refused_both_ways():
    from bridge.datastore import DataError

    with pytest.raises(DataError, match="not a class of bridge"):
        round_trip(_Pair(1, 2))
