"""Benchmark: Dask scaling of fracid's forward runs, and the limit of one client.

1. Real model: the KNN population of the bundled demo (Gregoire beam, gradient damage, kappa_i, beta
   and c at Sobol points of the demo's bounds, ``--population`` runs) through
   :func:`fracid.inverse.core.runs.run_population` (``run_batch`` with a fresh run store on the client):
   serial, the default process pool with 2 workers, and a ``dask.distributed.LocalCluster`` (processes,
   one thread each) with 1 and 2 workers. Efficiency = T(1) / (k T(k)) between the Dask runs.
2. Simulated cluster: a stand-in model (``time.sleep(d)``, returning a record of the demo's shape)
   through the same ``run_batch`` path with a run store, on a LocalCluster of many one-thread workers
   in this process (``processes=False``): the orchestration overhead per task,
   (wall - tasks d / workers) / tasks, and the task rate of the client (d = 0).
3. Run store: records per second written by ``RunStore.put`` (a stored record of case 1 re-written under
   new keys), alone and with the decoding ``run_batch`` does for each record it stores.
4. From 2 and 3: the number of workers beyond which one client limits, for forward runs of 1 s and 10 s.

    OPENBLAS_NUM_THREADS=1 python benchmarks/dask_scaling.py [--population 16] [--out docs/speed/dask]
        [--workers 8,16,32] [--durations 0,0.01,0.1] [--tasks 1000] [--skip-real]

Writes ``results.json`` and ``scaling.png`` in ``--out``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fracid.runtime.batch import BatchStats, run_batch  # noqa: E402
from fracid.config import build_data, build_operator, build_space  # noqa: E402
from fracid.inverse.core.runs import run_key, run_population  # noqa: E402
from fracid.inverse.methods.knn import design  # noqa: E402
from fracid.runtime.executors import make_executor  # noqa: E402
from fracid.store.runs import RunStore, key_for  # noqa: E402
from fracid.store.records import decode_record, encode_record  # noqa: E402
from demo_setup import demo_config  # noqa: E402


# -- 1. real model ---------------------------------------------------------------------------------


def demo_population(n: int):
    cfg = demo_config()
    operator = build_operator(cfg, build_data(cfg))
    space = build_space(cfg)
    return operator, design(space, n, "sobol")


def dask_cluster(workers: int, processes: bool = True):
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=processes, dashboard_address=None)
    client = Client(cluster)
    client.wait_for_workers(workers)
    return cluster, client


def time_population(label, operator, points, make, workdir):
    """Wall time of the population through a fresh run store; start-up of the executor timed apart."""
    start = time.perf_counter()
    executor, closer = make()
    ready = time.perf_counter()
    path = Path(workdir) / f"{label}.sqlite"
    stats = BatchStats()
    with RunStore(path) as store:
        records = run_population(operator, points, executor=executor, store=store, progress=False, stats=stats,
                                 study=label)
    end = time.perf_counter()
    closer()
    failed = sum(not r.ok for r in records)
    out = {"label": label, "startup_s": ready - start, "population_s": end - ready, "runs": len(records),
           "failed": failed, "compute_s": stats.compute_seconds, "store": str(path)}
    print(f"  {label:12s} start-up {out['startup_s']:6.2f} s, population {out['population_s']:7.2f} s "
          f"(sum of run times {stats.compute_seconds:7.2f} s, {failed} failed)", flush=True)
    return out, np.array([r.y for r in records])


def real_model(n: int, workdir) -> dict:
    operator, points = demo_population(n)
    start = time.perf_counter()
    run_key(operator, points[0])  # the first key of a process also hashes the forward code
    first_key_s = time.perf_counter() - start
    start = time.perf_counter()
    for x in points:
        run_key(operator, x)
    key_s = (time.perf_counter() - start) / len(points)
    print(f"real model: demo KNN population, {len(points)} runs, {operator.n_outputs} outputs; run key "
          f"{1e3 * key_s:.2f} ms each (the first of a process {1e3 * first_key_s:.0f} ms)", flush=True)

    def serial():
        return make_executor("serial"), lambda: None

    def pool2():
        pool = make_executor(2)
        list(pool.map(abs, [-1, -2]))  # start its 2 workers (spawned at the first submit)
        return pool, lambda: pool.shutdown()

    def dask(k):
        def make():
            cluster, client = dask_cluster(k)
            return client, lambda: (client.close(), cluster.close())
        return make

    cases, ys = [], {}
    for label, make in (("serial", serial), ("dask-1", dask(1)), ("dask-2", dask(2)), ("pool-2", pool2)):
        case, ys[label] = time_population(label, operator, points, make, workdir)
        cases.append(case)
    t = {c["label"]: c["population_s"] for c in cases}
    reference = ys["serial"]
    scale = np.nanmax(np.abs(reference))
    for case in cases:
        case["max_y_difference_to_serial"] = float(np.nanmax(np.abs(ys[case["label"]] - reference)) / scale)
    efficiency = t["dask-1"] / (2 * t["dask-2"])
    print(f"  Dask efficiency with 2 workers T(1) / (2 T(2)) = {efficiency:.2f}; speed-up over serial: "
          f"dask-2 {t['serial'] / t['dask-2']:.2f}, pool-2 {t['serial'] / t['pool-2']:.2f}", flush=True)
    return {"population": len(points), "outputs": int(operator.n_outputs), "parameters": list(operator.names),
            "run_key_s": key_s, "first_run_key_s": first_key_s, "cases": cases, "efficiency_dask_2": efficiency,
            "speedup_dask_2_over_serial": t["serial"] / t["dask-2"], "speedup_pool_2_over_serial": t["serial"] / t["pool-2"],
            "mean_run_s": cases[0]["compute_s"] / len(points)}


# -- 2. simulated cluster --------------------------------------------------------------------------


def standin(task) -> dict:
    """A stand-in model: sleeps ``d`` seconds and returns a record shaped like a forward run's."""
    d, i, p, n, reached = task
    if d > 0:
        time.sleep(d)
    rng = np.random.default_rng(i)
    return {"x": rng.random(p), "y": rng.random(n), "status": "ok", "error": "", "reached": [n] * reached,
            "seconds": float(d), "retried": False}


def simulated(client, workers: int, d: float, tasks: int, shape, workdir, store: bool = True) -> dict:
    p, n, reached = shape
    items = [(d, i, p, n, reached) for i in range(tasks)]
    keys = [key_for(bench="dask_scaling", d=d, workers=workers, i=i, t=time.time()) for i in range(tasks)]
    stats = BatchStats()
    path = Path(workdir) / f"sim-{workers}-{d}-{store}.sqlite"
    start = time.perf_counter()
    if store:
        with RunStore(path) as run_store:
            run_batch(standin, items, executor=client, store=run_store, keys=keys, progress=False, stats=stats)
    else:
        run_batch(standin, items, executor=client, progress=False, stats=stats)
    wall = time.perf_counter() - start
    ideal = tasks * d / workers
    out = {"workers": workers, "d_s": d, "tasks": tasks, "store": store, "wall_s": wall, "ideal_s": ideal,
           "overhead_per_task_ms": 1e3 * (wall - ideal) / tasks, "tasks_per_s": tasks / wall,
           "efficiency": ideal / wall if ideal > 0 else None}
    print(f"  {workers:3d} workers, d = {d:5.3f} s, {tasks} tasks{'' if store else ' (no store)'}: wall {wall:6.2f} s, "
          f"ideal {ideal:6.2f} s, overhead {out['overhead_per_task_ms']:6.2f} ms/task, "
          f"{out['tasks_per_s']:7.1f} tasks/s", flush=True)
    return out


def simulated_cluster(worker_counts, durations, tasks, shape, workdir) -> list:
    print(f"simulated cluster: stand-in tasks, {tasks} per case, LocalCluster(processes=False, threads_per_worker=1)",
          flush=True)
    out = []
    for workers in worker_counts:
        cluster, client = dask_cluster(workers, processes=False)
        try:
            run_batch(standin, [(0.0, i, *shape) for i in range(2 * workers)], executor=client, progress=False)  # warm-up
            for d in durations:
                out.append(simulated(client, workers, d, tasks, shape, workdir))
            if 0.0 in durations:
                out.append(simulated(client, workers, 0.0, tasks, shape, workdir, store=False))
        finally:
            client.close()
            cluster.close()
    return out


# -- 3. run store ----------------------------------------------------------------------------------


def store_throughput(record: dict, count: int, workdir) -> dict:
    blob = encode_record(record)
    keys = [key_for(bench="store", i=i, t=time.time()) for i in range(count)]
    out = {"record_bytes": len(blob), "records": count}
    for label, decode in (("put", False), ("put_and_decode", True)):
        with RunStore(Path(workdir) / f"store-{label}.sqlite") as store:
            start = time.perf_counter()
            for key in keys:
                store.put(key, blob, status="ok", seconds=1.0, study="bench")
                if decode:
                    decode_record(blob)
            seconds = time.perf_counter() - start
        out[f"{label}_per_s"] = count / seconds
    start = time.perf_counter()
    for _ in range(count):
        encode_record(record)
    out["encode_per_s"] = count / (time.perf_counter() - start)
    print(f"run store: {count} records of {len(blob)} bytes; put {out['put_per_s']:.0f}/s, put + decode "
          f"{out['put_and_decode_per_s']:.0f}/s (encoding, done by the worker: {out['encode_per_s']:.0f}/s)", flush=True)
    return out


def stored_record(real: dict | None) -> dict:
    """A record of case 1 (from the Dask 2-worker store), else a stand-in of the demo's shape."""
    if real is not None:
        path = next(c["store"] for c in real["cases"] if c["label"] == "dask-2")
        with RunStore(path, readonly=True) as store:
            return store.get(store.keys()[0])
    return standin((0.0, 0, 3, 24, 1))


# -- 4. the limit of one client --------------------------------------------------------------------


def client_limit(sim: list, store: dict, run_seconds=(1.0, 10.0)) -> dict:
    """Tasks per second one client absorbs (the d = 0 rate with the store, the slowest worker count) and
    the workers that keep it busy with runs of ``run_seconds``."""
    rates = [s["tasks_per_s"] for s in sim if s["d_s"] == 0.0 and s["store"]]
    overheads = [s["overhead_per_task_ms"] for s in sim if s["d_s"] > 0]
    rate = min(rates) if rates else None
    out = {"client_tasks_per_s": rate, "store_puts_per_s": store["put_and_decode_per_s"],
           "max_overhead_per_task_ms": max(overheads) if overheads else None, "workers_at_limit": {}}
    if rate:
        for t in run_seconds:
            out["workers_at_limit"][f"{t:g} s"] = rate * t
        print(f"one client: {rate:.0f} tasks/s (stand-in, with the store); it limits beyond "
              + ", ".join(f"{rate * t:.0f} workers for {t:g} s runs" for t in run_seconds), flush=True)
    return out


# -- figure ----------------------------------------------------------------------------------------


def figure(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    real, sim = results.get("real_model"), results["simulated"]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    if real is not None:
        ax = axes[0]
        labels = [c["label"] for c in real["cases"]]
        times = [c["population_s"] for c in real["cases"]]
        bars = ax.bar(labels, times, color=["0.6", "C0", "C0", "C1"])
        for bar, c in zip(bars, real["cases"]):
            ax.text(bar.get_x() + bar.get_width() / 2, bar.get_height(), f"{c['population_s']:.0f} s",
                    ha="center", va="bottom")
        ax.set_ylabel("wall time of the population [s]")
        ax.set_title(f"demo KNN population, {real['population']} runs, 2 cores\n"
                     f"Dask efficiency T(1)/(2 T(2)) = {real['efficiency_dask_2']:.2f}")
    else:
        axes[0].set_axis_off()
    ax = axes[1]
    for d in sorted({s["d_s"] for s in sim}):
        rows = sorted((s for s in sim if s["d_s"] == d and s["store"]), key=lambda s: s["workers"])
        ax.plot([s["workers"] for s in rows], [s["overhead_per_task_ms"] for s in rows], "o-", label=f"d = {d:g} s")
    ax.set_xscale("log", base=2)
    ax.set_xlabel("workers (threads of a LocalCluster in the client's process)")
    ax.set_ylabel("overhead per task [ms]")
    ax.set_title("stand-in tasks through run_batch + run store")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--population", type=int, default=16)
    parser.add_argument("--workers", default="8,16,32", help="worker counts of the simulated cluster")
    parser.add_argument("--durations", default="0,0.01,0.1", help="stand-in task durations [s]")
    parser.add_argument("--tasks", type=int, default=1000, help="tasks per simulated case")
    parser.add_argument("--store-records", type=int, default=5000)
    parser.add_argument("--skip-real", action="store_true", help="skip case 1 (the real model)")
    parser.add_argument("--out", type=Path, default=Path("docs/speed/dask"))
    args = parser.parse_args(argv)
    worker_counts = [int(w) for w in args.workers.split(",")]
    durations = [float(d) for d in args.durations.split(",")]
    started = time.perf_counter()
    results = {"command": "python benchmarks/dask_scaling.py " + " ".join(argv if argv is not None else sys.argv[1:]),
               "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               "machine": {"cores": os.cpu_count(), "python": platform.python_version(),
                           "platform": platform.platform(),
                           "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")}}
    import dask
    import distributed

    import fracid

    results["versions"] = {"fracid": fracid.__version__, "dask": dask.__version__, "distributed": distributed.__version__}
    with tempfile.TemporaryDirectory() as workdir:
        real = None if args.skip_real else real_model(args.population, workdir)
        results["real_model"] = real
        record = stored_record(real)
        shape = (len(record["x"]), len(record["y"]), len(record["reached"]))
        results["stored_record_shape"] = {"x": shape[0], "y": shape[1], "reached": shape[2]}
        results["store"] = store_throughput(record, args.store_records, workdir)
        results["simulated"] = simulated_cluster(worker_counts, durations, args.tasks, shape, workdir)
    if real is not None:
        for case in real["cases"]:
            case.pop("store")
    results["client_limit"] = client_limit(results["simulated"], results["store"])
    results["benchmark_wall_s"] = time.perf_counter() - started
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    figure(results, args.out / "scaling.png")
    print(f"wrote {args.out / 'results.json'} and {args.out / 'scaling.png'} ({results['benchmark_wall_s']:.0f} s)")
    return results


if __name__ == "__main__":
    main()
