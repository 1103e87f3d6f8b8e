"""RunStore: lossless records, stable keys, replace, persistence, and survival of a SIGKILL mid-write."""

import json
import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import fracid
from fracid.store.runs import RunStore, key_for
from fracid.store.records import decode_record, encode_record

SRC = str(Path(fracid.__file__).resolve().parents[1])


def sample_record():
    return {
        "status": "ok",
        "force": np.linspace(0.0, 1.0, 7) ** 3 + 1e-17,
        "steps": np.arange(5, dtype=np.int32),
        "big": np.array([2**62, -3], dtype=np.int64),
        "field": np.arange(12.0).reshape(3, 4)[:, ::2],  # 2D, not contiguous
        "fortran": np.asfortranarray(np.arange(6.0).reshape(2, 3)),
        "flags": np.array([True, False]),
        "empty": np.empty((0, 3)),
        "special": np.array([np.nan, np.inf, -np.inf, -0.0]),
        "scalar": np.float64(0.1) * 3,
        "nested": {"params": {"E": 20000.0, "c": 1.0}, "list": [1, 2.5, None, "x", [np.int64(3)]]},
        "name": "bar",
    }


def assert_same(a, b):
    """``a`` read back equals ``b`` written; numpy scalars come back as Python numbers."""
    if isinstance(b, np.generic):
        b = b.item()
    assert type(a) is type(b), (a, b)
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape
        assert a.tobytes() == np.ascontiguousarray(b).tobytes()  # bit for bit (nan, -0.0 included)
    elif isinstance(a, dict):
        assert a.keys() == b.keys()
        for k in a:
            assert_same(a[k], b[k])
    elif isinstance(a, list):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            assert_same(x, y)
    else:
        assert a == b


def test_records_round_trip_losslessly(tmp_path):
    record = sample_record()
    back = decode_record(encode_record(record))
    assert_same(back, record)
    assert back["field"].flags.writeable and back["field"].flags.c_contiguous
    with RunStore(tmp_path / "runs.sqlite") as store:
        store.put("k", record, status="ok", seconds=1.5, study="s")
        assert_same(store.get("k"), record)
        assert store.info("k")["status"] == "ok" and store.info("k")["seconds"] == 1.5


def test_structured_and_text_arrays_round_trip():
    dtype = np.dtype([("x", "<f8"), ("n", ">i4", (2,)), ("sub", [("q", "<f4")])])
    record = {"table": np.zeros(3, dtype=dtype), "names": np.array(["ab", "c"])}
    record["table"]["n"] = [[1, 2], [3, 4], [5, 6]]
    back = decode_record(encode_record(record))
    assert back["table"].dtype == dtype and back["table"].tobytes() == record["table"].tobytes()
    assert back["names"].tolist() == ["ab", "c"]


@pytest.mark.parametrize(
    "record, words",
    [
        ({"f": lambda x: x}, ["record['f']", "function"]),
        ({"a": np.array([object()])}, ["record['a']", "object"]),
        ({1: 2.0}, ["dict keys must be str"]),
        ([1, 2], ["must be a dict", "list"]),
    ],
)
def test_unstorable_records_are_named(record, words):
    with pytest.raises(TypeError) as info:
        encode_record(record)
    for word in words:
        assert word in str(info.value)


def test_keys_ignore_dict_order_and_round_off():
    params = fracid.DamageParameters(E=20000.0, kappa_i=1e-4, beta=300.0)
    bar = fracid.BarWithWeakZone(n_elements=200)
    a = key_for(model="gradient", specimen=bar, params=params, x=np.array([0.1 + 0.2, 2.0]), control={"a": 1, "b": 2})
    b = key_for(control={"b": 2, "a": 1}, x=[0.3, 2], params=params, specimen=bar, model="gradient")
    assert a == b and len(a) == 64
    assert key_for(x=[0.3, 2.0]) != key_for(x=[0.3000001, 2.0])
    assert key_for(specimen=bar) != key_for(specimen=fracid.BarWithWeakZone(n_elements=400))
    assert key_for(params=params) != key_for(params=params.replace(c=2.0))
    assert key_for(n=200) == key_for(n=200.0) and key_for(z=-0.0) == key_for(z=0.0)


@dataclass
class _Spec:
    mesh: object


def test_key_refuses_unknown_objects_naming_them():
    with pytest.raises(TypeError, match=r"specimen\.mesh"):
        key_for(specimen=_Spec(object()))
    with pytest.raises(TypeError, match=r"dict keys must be str"):
        key_for(control={1: "cmod"})


def test_keys_are_the_same_in_another_process():
    parts = {"model": "gradient", "x": [20000.0, 1e-4, 0.99, 300.0, 1.0], "mesh": {"h_fine": 1.0, "n": 200}}
    here = key_for(**parts)
    code = "import json, sys; from fracid.store.runs import key_for; print(key_for(**json.loads(sys.argv[1])))"
    env = dict(os.environ, PYTHONHASHSEED="12345")
    mixed = dict(reversed(list(parts.items())))
    args = [sys.executable, "-c", code, json.dumps(mixed)]
    out = subprocess.run(args, capture_output=True, text=True, env=env, check=False)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == here


def test_put_replaces_and_persists_across_reopen(tmp_path):
    path = tmp_path / "runs.sqlite"
    with RunStore(path) as store:
        assert store.journal_mode == "wal"
        store.put("a", {"v": np.array([1.0])}, status="failed", seconds=0.1, study="s1")
        store.put("a", {"v": np.array([2.0])}, status="ok", seconds=0.2, study="s1")
        store.put("b", {"v": 3}, status="ok", seconds=0.3, study="s2")
        assert len(store) == 2 and "a" in store and "zz" not in store
    with RunStore(path) as store:
        assert store.get("a")["v"].tolist() == [2.0] and store.info("a")["status"] == "ok"
        assert store.keys() == ["a", "b"] and store.keys("s2") == ["b"] and store.keys("none") == []
        assert set(store.get_many(["a", "b", "missing"])) == {"a", "b"}
        assert store.get("missing") is None
    assert store.closed
    with pytest.raises(RuntimeError, match="closed"):
        store.get("a")


def test_read_only_store_and_clear_errors(tmp_path):
    path = tmp_path / "runs.sqlite"
    with pytest.raises(FileNotFoundError, match="read-only"):
        RunStore(path, readonly=True)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        RunStore(tmp_path / "no" / "such" / "dir.sqlite")
    with RunStore(path) as store:
        store.put("a", {}, status="ok", seconds=0.0)
        with pytest.raises(TypeError, match="sent to another process"):
            import pickle

            pickle.dumps(store)
    with RunStore(path, readonly=True) as reader:
        assert reader.get("a") == {}
        with pytest.raises(PermissionError):
            reader.put("b", {}, status="ok", seconds=0.0)
    (tmp_path / "junk.sqlite").write_bytes(b"not a database, just some bytes" * 100)
    with pytest.raises(sqlite3.DatabaseError, match="run store"):
        RunStore(tmp_path / "junk.sqlite")


WRITER = textwrap.dedent(
    """
    import sys
    sys.path.insert(0, {src!r})
    import numpy as np
    from fracid.store.runs import RunStore
    store = RunStore(sys.argv[1])
    for i in range(100000):
        store.put(f"run{{i:06d}}", {{"i": i, "data": np.full(20000, float(i))}}, status="ok", seconds=0.0)
        print(i, flush=True)
    """
)


def test_kill_while_writing_loses_no_committed_row(tmp_path):
    path = tmp_path / "runs.sqlite"
    child = subprocess.Popen(
        [sys.executable, "-c", WRITER.format(src=SRC), str(path)], stdout=subprocess.PIPE, text=True
    )
    try:
        last = -1
        deadline = time.monotonic() + 60
        while last < 60 and time.monotonic() < deadline:
            line = child.stdout.readline()
            assert line, "the writer stopped early"
            last = int(line)
        os.kill(child.pid, signal.SIGKILL)
    finally:
        child.kill()
        child.wait()
        child.stdout.close()
    assert last >= 60
    with RunStore(path) as store:
        assert store._conn.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
        keys = store.keys()
        n = len(keys)
        assert n >= last + 1  # every row reported committed is there (and maybe the next one)
        assert keys == [f"run{i:06d}" for i in range(n)]
        for key, record in store.get_many(keys).items():
            i = int(key[3:])
            assert record["i"] == i and record["data"].shape == (20000,) and np.all(record["data"] == i)
        store.put("after", {"ok": True}, status="ok", seconds=0.0)  # still writable
        assert len(store) == n + 1
