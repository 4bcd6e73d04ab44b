"""Data-only storage of Python result objects in HDF5: what the stage cache keeps of a stage's ``data``.

A result folder, and the stage cache inside it, travels between people, so what is stored there must be
data that reading can only turn back into data: no pickle, which runs whatever code a file names.
:func:`write` encodes an object tree into an h5py group and :func:`read` decodes it:

* ``tree`` - the tree as JSON text: None, bool, int, float and str as themselves, every other node an
  object ``{"$": kind, ...}``; ``arrays/<n>`` - each numpy array of the tree, one dataset (named by its
  number; the tree's ``{"$": "array", "ref": n}`` points at it, an array met twice is stored once).
* kinds: ``complex``, ``bytes``, ``list``, ``tuple``, ``dict`` (its items as ``[key, value]`` pairs:
  keys are data, never HDF5 names), ``array`` (numeric, bool, complex or bytes; read-only and Fortran
  order kept), ``strarray`` (unicode arrays, as JSON strings), ``scalar`` (a numpy scalar, dtype kept),
  ``sparse`` (a scipy.sparse csr/csc/bsr/coo matrix or array: format, shape and its arrays; the same
  format is rebuilt), and three kinds of our own classes, named ``"module:qualname"`` with a module
  under ``bridge.``:
  ``dataclass`` (every field, ``init=False`` ones too, by name), ``namedtuple`` (every field by name)
  and ``object``, a class that states its constructor arguments as data: it defines
  ``data_arguments(self) -> dict[str, Any]`` and the classmethod ``from_data_arguments(cls, arguments)``
  that builds an equal object from them (e.g. :class:`bridge.flutter.tables.DerivativeTable`).

A dataclass is rebuilt with ``object.__new__`` and its stored field values set as they were
(``object.__setattr__``, so frozen ones too): neither ``__init__`` nor ``__post_init__`` runs, the object
is the one that was stored, not one recomputed from its arguments.  A dataclass that holds attributes
other than its fields is refused when written.  A NamedTuple is rebuilt with ``_make``; an ``object``
through its own ``from_data_arguments`` (its constructor, so its checks run again).

Reading instantiates nothing else: a class whose module is not ``bridge.<...>``, that is not defined
where the tag says, or is not of the kind the tag says, a missing or unknown field, an unknown kind, a
dataset of another type (object, compound) or a node of the wrong shape raise :class:`DataError`
with a one-line reason, and so does writing an object outside this list.
"""

from __future__ import annotations

import dataclasses
import json
import re
import sys
from importlib import import_module
from typing import Any

import numpy as np

__all__ = ["write", "read", "member", "DataError", "FORMAT"]

FORMAT = "1"  # the ``datastore`` attribute of a written group; bump when the encoding changes
_MODULE = re.compile(r"bridge(\.[A-Za-z_][A-Za-z0-9_]*)+")
_QUALNAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*")
_ARRAY_KINDS = "biufcS"          # dtypes kept as datasets: bool, integers, floats, complex, bytes
_SCALAR_KINDS = "biufc"
_NUMBER = (int, float)
_SPARSE_PARTS = {"csr": ("data", "indices", "indptr"), "csc": ("data", "indices", "indptr"),
                 "bsr": ("data", "indices", "indptr"), "coo": ("data", "row", "col")}


class DataError(ValueError):
    """An object that cannot be stored as data, or a stored tree that does not read back as data."""


# ----------------------------------------------------------------------------------------------- writing
def write(group: Any, obj: Any) -> None:
    """Encode ``obj`` into the (empty) h5py ``group``: ``tree`` (JSON text) and ``arrays/<n>`` datasets.
    Anything the module docstring does not list is a :class:`DataError` naming where it sits."""
    arrays = group.create_group("arrays")
    tree = _Writer(arrays).node(obj, "data", ())
    group.attrs["datastore"] = FORMAT
    group["tree"] = json.dumps(tree, separators=(",", ":"))


def _type_name(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _is_namedtuple(cls: type) -> bool:
    return issubclass(cls, tuple) and isinstance(getattr(cls, "_fields", None), tuple) and hasattr(cls, "_make")


def _has_protocol(cls: type) -> bool:
    return callable(getattr(cls, "data_arguments", None)) and callable(getattr(cls, "from_data_arguments", None))


class _Writer:
    """Encodes an object tree into JSON nodes, its arrays into datasets of ``arrays``."""

    def __init__(self, arrays: Any):
        self.arrays = arrays
        self.refs: dict[int, str] = {}   # id(array) -> its dataset, so an array met twice is stored once
        self.kept: list[Any] = []        # those arrays, alive until the end (ids stay unique)

    def node(self, obj: Any, path: str, active: tuple[int, ...]) -> Any:
        t = type(obj)
        if obj is None or t in (bool, int, float, str):   # JSON keeps these exactly (NaN and infinities too)
            return obj
        if t is complex:
            return {"$": "complex", "re": obj.real, "im": obj.imag}
        if t is bytes:
            return {"$": "bytes", "ref": self.array(np.frombuffer(obj, dtype=np.uint8), path)}
        if isinstance(obj, np.generic):
            if obj.dtype.kind not in _SCALAR_KINDS:
                raise DataError(f"cannot store {path}: numpy scalar of dtype {obj.dtype} (numbers only)")
            value = obj.item()
            return {"$": "scalar", "dtype": obj.dtype.str,
                    "value": [value.real, value.imag] if obj.dtype.kind == "c" else value}
        if t is np.ndarray:
            if obj.dtype.kind == "U":
                return {"$": "strarray", "dtype": obj.dtype.str, "shape": list(obj.shape),
                        "items": obj.ravel().tolist()}
            if obj.dtype.kind not in _ARRAY_KINDS or obj.dtype.fields is not None:
                raise DataError(f"cannot store {path}: array of dtype {obj.dtype} (numbers, bool, text only)")
            node = {"$": "array", "ref": self.array(obj, path)}
            if obj.ndim > 1 and obj.flags.f_contiguous and not obj.flags.c_contiguous:
                node["order"] = "F"
            if not obj.flags.writeable:
                node["readonly"] = True
            return node
        if id(obj) in active:
            raise DataError(f"cannot store {path}: it contains itself")
        active = (*active, id(obj))
        if t in (list, tuple):
            return {"$": t.__name__, "items": [self.node(x, f"{path}[{i}]", active) for i, x in enumerate(obj)]}
        if t is dict:
            return {"$": "dict", "items": [[self.node(k, f"{path} key {k!r}", active),
                                            self.node(v, f"{path}[{k!r}]", active)] for k, v in obj.items()]}
        if _is_sparse(obj):
            return self.sparse(obj, path)
        name = _type_name(t)
        if not _MODULE.fullmatch(t.__module__) or not _QUALNAME.fullmatch(t.__qualname__):
            raise DataError(f"cannot store {path}: {name} is not data (not a class of bridge)")
        if _has_protocol(t):
            arguments = obj.data_arguments()
            if type(arguments) is not dict or not all(type(k) is str for k in arguments):
                raise DataError(f"cannot store {path}: {name}.data_arguments() is not a dict with str keys")
            return {"$": "object", "type": name,
                    "arguments": {k: self.node(v, f"{path}.{k}", active) for k, v in arguments.items()}}
        if dataclasses.is_dataclass(t) and "__dataclass_fields__" in vars(t):
            names = [f.name for f in dataclasses.fields(t)]
            extra = sorted(set(getattr(obj, "__dict__", {})) - set(names))
            unset = [n for n in names if not hasattr(obj, n)]
            if extra or unset:
                raise DataError(f"cannot store {path}: {name} " + (f"holds attributes that are not fields: "
                                                                   f"{', '.join(extra)}" if extra else
                                                                   f"has no value for the field {unset[0]}"))
            return {"$": "dataclass", "type": name,
                    "fields": {n: self.node(getattr(obj, n), f"{path}.{n}", active) for n in names}}
        if _is_namedtuple(t):
            return {"$": "namedtuple", "type": name,
                    "fields": {n: self.node(v, f"{path}.{n}", active) for n, v in zip(t._fields, obj, strict=True)}}
        raise DataError(f"cannot store {path}: {name} is neither a dataclass, a NamedTuple nor a class with "
                        "data_arguments/from_data_arguments")

    def array(self, a: np.ndarray, path: str) -> str:
        if id(a) in self.refs:
            return self.refs[id(a)]
        ref = str(len(self.refs))
        try:
            self.arrays.create_dataset(ref, data=np.asarray(a, order="C"))
        except (TypeError, ValueError) as exc:
            raise DataError(f"cannot store {path}: {exc}") from None
        self.refs[id(a)] = ref
        self.kept.append(a)
        return ref

    def sparse(self, m: Any, path: str) -> dict:
        fmt = type(m).__name__.split("_")[0]
        if _sparse_classes().get(type(m).__name__) is not type(m):
            raise DataError(f"cannot store {path}: sparse {type(m).__name__} (csr, csc, bsr, coo only)")
        node = {"$": "sparse", "class": type(m).__name__, "shape": [int(n) for n in m.shape]}
        for part in _SPARSE_PARTS[fmt]:
            node[part] = self.node(np.asarray(getattr(m, part)), f"{path}.{part}", ())
        return node


def _sparse_classes() -> dict[str, type]:
    import scipy.sparse as sp

    names = [f"{fmt}_{kind}" for fmt in _SPARSE_PARTS for kind in ("matrix", "array")]
    return {n: getattr(sp, n) for n in names if hasattr(sp, n)}


def _is_sparse(obj: Any) -> bool:
    sp = sys.modules.get("scipy.sparse")   # not imported: nothing can be sparse
    return sp is not None and sp.issparse(obj)


# ----------------------------------------------------------------------------------------------- reading
def read(group: Any) -> Any:
    """Decode what :func:`write` stored in the h5py ``group``; anything else is a :class:`DataError`."""
    import h5py

    if group.attrs.get("datastore") != FORMAT:
        raise DataError(f"not a data tree of format {FORMAT} (datastore attribute {group.attrs.get('datastore')!r})")
    text = member(group, "tree", h5py.Dataset)
    if text.shape != () or text.dtype.kind not in "OS":
        raise DataError("tree: not a text dataset")
    raw = text[()]
    try:
        tree = json.loads(raw.decode() if isinstance(raw, bytes) else raw)
    except (ValueError, TypeError, AttributeError) as exc:
        raise DataError(f"tree: not JSON text ({exc})") from None
    return _Reader(member(group, "arrays", h5py.Group)).node(tree, "data")


def member(group: Any, name: str, kind: type) -> Any:
    """``group[name]``, which must be a hard link to an object of ``kind`` stored inside the file."""
    import h5py

    link = group.get(name, getlink=True)
    if link is None:
        raise DataError(f"{name}: missing")
    if not isinstance(link, h5py.HardLink):
        raise DataError(f"{name}: a {type(link).__name__}, not an object of this file")
    obj = group[name]
    if not isinstance(obj, kind):
        raise DataError(f"{name}: a {type(obj).__name__}, expected a {kind.__name__}")
    if isinstance(obj, h5py.Dataset) and (obj.external or obj.is_virtual):
        raise DataError(f"{name}: data stored outside the file")
    return obj


def _dtype(text: Any, kinds: str, path: str) -> np.dtype:
    try:
        dt = np.dtype(text) if isinstance(text, str) else None
    except TypeError:
        dt = None
    if dt is None or dt.kind not in kinds or dt.fields is not None or dt.subdtype is not None:
        raise DataError(f"{path}: dtype {text!r} is not one of the kinds {kinds}")
    return dt


def _keys(node: dict, path: str, *required: str, optional: tuple[str, ...] = ()) -> None:
    missing = [k for k in required if k not in node]
    unknown = [k for k in node if k != "$" and k not in required and k not in optional]
    if missing or unknown:
        raise DataError(f"{path}: {node['$']} node " + (f"lacks {', '.join(missing)}" if missing else
                                                        f"has unknown entries {', '.join(unknown)}"))


def _of(value: Any, types: tuple[type, ...], path: str, what: str) -> Any:
    """``value`` when its type is exactly one of ``types`` (a bool is no number here unless bool is named)."""
    if type(value) not in types:
        raise DataError(f"{path}: {what} expected, found {type(value).__name__}")
    return value


_NODE_KINDS = ("complex", "bytes", "list", "tuple", "dict", "scalar", "array", "strarray", "sparse", "dataclass",
               "namedtuple", "object")


class _Reader:
    """Decodes a tree node by node (``k_<kind>``), reading the arrays it points at from ``arrays``."""

    def __init__(self, arrays: Any):
        self.arrays = arrays
        self.done: dict[str, np.ndarray] = {}   # arrays read, by reference

    def node(self, n: Any, path: str) -> Any:
        if n is None or type(n) in (bool, int, float, str):
            return n
        if type(n) is not dict or type(n.get("$")) is not str:
            raise DataError(f"{path}: a {type(n).__name__} where a node was expected (wrong node kind)")
        kind = n["$"]
        if kind not in _NODE_KINDS:
            raise DataError(f"{path}: unknown node kind {kind!r}")
        return getattr(self, f"k_{kind}")(n, path)

    def items(self, n: dict, path: str) -> list:
        return _of(n["items"], (list,), path, "a list of items")

    def k_complex(self, n: dict, path: str) -> complex:
        _keys(n, path, "re", "im")
        return complex(_of(n["re"], _NUMBER, path, "a number"), _of(n["im"], _NUMBER, path, "a number"))

    def k_bytes(self, n: dict, path: str) -> bytes:
        _keys(n, path, "ref")
        a = self.dataset(n["ref"], path)
        if a.dtype != np.uint8 or a.ndim != 1:
            raise DataError(f"{path}: bytes stored as {a.dtype} of shape {a.shape}, not uint8 (n,)")
        return a.tobytes()

    def k_list(self, n: dict, path: str) -> list:
        _keys(n, path, "items")
        return [self.node(x, f"{path}[{i}]") for i, x in enumerate(self.items(n, path))]

    def k_tuple(self, n: dict, path: str) -> tuple:
        return tuple(self.k_list(n, path))

    def k_dict(self, n: dict, path: str) -> dict:
        _keys(n, path, "items")
        out = {}
        for i, pair in enumerate(self.items(n, path)):
            if type(pair) is not list or len(pair) != 2:
                raise DataError(f"{path}: item {i} is not a [key, value] pair")
            key = self.node(pair[0], f"{path} key {i}")
            try:
                hash(key)
            except TypeError:
                raise DataError(f"{path}: key {i} is a {type(key).__name__}, which cannot be a key") from None
            out[key] = self.node(pair[1], f"{path}[{key!r}]")
        return out

    def k_scalar(self, n: dict, path: str) -> np.generic:
        _keys(n, path, "dtype", "value")
        dt = _dtype(n["dtype"], _SCALAR_KINDS, path)
        v = n["value"]
        if dt.kind == "c":
            if type(v) is not list or len(v) != 2:
                raise DataError(f"{path}: a complex scalar needs [re, im]")
            v = complex(_of(v[0], _NUMBER, path, "a number"), _of(v[1], _NUMBER, path, "a number"))
        else:
            v = _of(v, (bool, *_NUMBER), path, "a number")
        try:
            return dt.type(v)
        except (OverflowError, ValueError, TypeError) as exc:
            raise DataError(f"{path}: {exc}") from None

    def dataset(self, ref: Any, path: str) -> np.ndarray:
        """The array stored as ``arrays/<ref>`` (a fresh one at each call)."""
        import h5py

        if type(ref) is not str:
            raise DataError(f"{path}: array reference {ref!r} is not a name")
        try:
            ds = member(self.arrays, ref, h5py.Dataset)
        except DataError as exc:
            raise DataError(f"{path}: arrays/{exc}") from None
        _dtype(ds.dtype.str, _ARRAY_KINDS, f"{path} (arrays/{ref})")
        return np.asarray(ds[()])

    def k_array(self, n: dict, path: str) -> np.ndarray:
        _keys(n, path, "ref", optional=("order", "readonly"))
        ref = n["ref"]
        if ref in self.done:      # one array met twice when written: the same object again
            return self.done[ref]
        a = self.dataset(ref, path)
        if n.get("order", "C") not in ("C", "F"):
            raise DataError(f"{path}: order {n['order']!r} is neither C nor F")
        if n.get("order") == "F":
            a = np.asfortranarray(a)
        if _of(n.get("readonly", False), (bool,), path, "true or false"):
            a.setflags(write=False)
        self.done[ref] = a
        return a

    def k_strarray(self, n: dict, path: str) -> np.ndarray:
        _keys(n, path, "dtype", "shape", "items")
        dt = _dtype(n["dtype"], "U", path)
        shape = _of(n["shape"], (list,), path, "a shape")
        items = self.items(n, path)
        if not all(type(s) is int and s >= 0 for s in shape) or not all(type(x) is str for x in items):
            raise DataError(f"{path}: a string array needs a shape of integers and str items")
        if int(np.prod(shape)) != len(items):
            raise DataError(f"{path}: {len(items)} items for shape {shape}")
        return np.array(items, dtype=dt).reshape(shape)

    def k_sparse(self, n: dict, path: str) -> Any:
        classes = _sparse_classes()
        name = n.get("class")
        if name not in classes:
            raise DataError(f"{path}: sparse class {name!r} (known: {', '.join(classes)})")
        cls, fmt = classes[name], name.split("_")[0]
        parts = _SPARSE_PARTS[fmt]
        _keys(n, path, "class", "shape", *parts)
        shape = _of(n["shape"], (list,), path, "a shape")
        if len(shape) != 2 or not all(type(s) is int and s >= 0 for s in shape):
            raise DataError(f"{path}: sparse shape {shape!r}")
        arrays = [self.node(n[p], f"{path}.{p}") for p in parts]
        if not all(type(a) is np.ndarray for a in arrays):
            raise DataError(f"{path}: the parts of a sparse matrix are arrays")
        try:
            m = cls((arrays[0], (arrays[1], arrays[2])) if fmt == "coo" else tuple(arrays), shape=tuple(shape))
        except (ValueError, TypeError, IndexError) as exc:
            raise DataError(f"{path}: {exc}") from None
        for p, a in zip(parts, arrays, strict=True):   # the stored arrays, not copies of other index dtypes
            if getattr(m, p).dtype != a.dtype:
                setattr(m, p, a)
        return m

    def cls(self, n: dict, path: str) -> type:
        tag = n.get("type")
        if type(tag) is not str or tag.count(":") != 1:
            raise DataError(f"{path}: type {tag!r} is not 'module:name'")
        module_name, qualname = tag.split(":")
        if not _MODULE.fullmatch(module_name) or not _QUALNAME.fullmatch(qualname) or "__main__" in module_name:
            raise DataError(f"{path}: type {tag!r} is not a class of bridge")
        try:
            obj: Any = import_module(module_name)
        except ImportError:
            raise DataError(f"{path}: type {tag!r}: no module {module_name}") from None
        for part in qualname.split("."):
            obj = getattr(obj, part, None)
        if not isinstance(obj, type) or obj.__module__ != module_name or obj.__qualname__ != qualname:
            raise DataError(f"{path}: type {tag!r} is not a class defined there")
        return obj

    def fields(self, n: dict, path: str, names: tuple[str, ...] | list[str], tag: str) -> dict:
        _keys(n, path, "type", "fields")
        given = _of(n["fields"], (dict,), path, "a table of fields")
        missing = [k for k in names if k not in given]
        unknown = [k for k in given if k not in names]
        if missing or unknown:
            raise DataError(f"{path}: {tag} " + (f"lacks the field {missing[0]}" if missing else
                                                 f"has no field {unknown[0]}"))
        return {k: self.node(given[k], f"{path}.{k}") for k in names}

    def k_dataclass(self, n: dict, path: str) -> Any:
        cls = self.cls(n, path)
        if not (dataclasses.is_dataclass(cls) and "__dataclass_fields__" in vars(cls)):
            raise DataError(f"{path}: {n['type']} is not a dataclass")
        values = self.fields(n, path, [f.name for f in dataclasses.fields(cls)], n["type"])
        obj = object.__new__(cls)
        for k, v in values.items():
            object.__setattr__(obj, k, v)
        return obj

    def k_namedtuple(self, n: dict, path: str) -> Any:
        cls = self.cls(n, path)
        if not _is_namedtuple(cls):
            raise DataError(f"{path}: {n['type']} is not a NamedTuple")
        return cls._make(self.fields(n, path, cls._fields, n["type"]).values())

    def k_object(self, n: dict, path: str) -> Any:
        _keys(n, path, "type", "arguments")
        cls = self.cls(n, path)
        if not _has_protocol(cls):
            raise DataError(f"{path}: {n['type']} does not rebuild from data (no data_arguments/from_data_arguments)")
        given = _of(n["arguments"], (dict,), path, "a table of arguments")
        arguments = {k: self.node(v, f"{path}.{k}") for k, v in given.items()}
        try:
            return cls.from_data_arguments(arguments)
        except DataError:
            raise
        except Exception as exc:   # e.g. a constructor's InputError on arguments it does not accept
            raise DataError(f"{path}: {n['type']} refused its arguments ({type(exc).__name__}: {exc})") from None
