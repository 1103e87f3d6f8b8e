"""A KNN population on the bar, shared by the kill-and-resume test and the child process it kills."""

import sys

import numpy as np

import fracid
from fracid.inverse.core.forward_operator import ForwardOperator, Observation
from fracid.inverse.core.space import ParameterSpace
from fracid.inverse.methods.knn import knn_search

N_RUNS = 120
SPACE = ParameterSpace(("c", "beta"), [0.5, 100.0], [4.0, 500.0])


def operator():
    bar = fracid.BarWithWeakZone(n_elements=60)
    return ForwardOperator([Observation(bar, np.linspace(0.004, 0.03, 16))], fracid.DamageParameters(), ("c", "beta"))


def data(op):
    y = op(np.array([2.0, 250.0])).y
    return y, np.eye(y.size) * (0.02 * np.abs(y).max()) ** 2


def search(op, store=None, executor=None, stats=None):
    y, C = data(op)
    return knn_search(op, y, C, SPACE, n=N_RUNS, method="lhs", seed=3, k=5, executor=executor, store=store,
                      progress=False, stats=stats)


def main(store_path):
    from fracid.runtime.executors import make_executor
    from fracid.store.runs import RunStore

    op = operator()
    with RunStore(store_path) as store, make_executor(2) as executor:
        search(op, store, executor)


if __name__ == "__main__":
    main(sys.argv[1])
