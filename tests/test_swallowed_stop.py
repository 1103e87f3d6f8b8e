"""A stop signal whose exception a library swallows (compiled code that cannot pass exceptions on prints
"Exception ignored in" and goes on: scipy's Sobol initialisation did, and a 1000-run identification then ran
to the end and exited 0) is raised again at the next checkpoint, without a traceback on stderr."""

import subprocess
import sys
import textwrap

PROGRAM = textwrap.dedent("""
    import os, signal, sys
    from fracid.runtime import exits, stops
    from fracid.runtime.batch import run_batch

    class SwallowsInDel:
        def __del__(self):  # an exception raised here is unraisable: Python prints it and goes on
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(10_000):  # the handler runs between bytecodes, here
                pass

    with exits.stop_signals():
        SwallowsInDel()  # made and collected at once
        print("went on", flush=True)
        try:
            run_batch(dict, [{"a": 1}, {"a": 2}], executor="serial", progress=False)
        except stops.Terminated:
            print("raised again at the checkpoint", flush=True)
    os._exit(0)
""")


def test_a_swallowed_stop_is_raised_again_at_the_next_checkpoint():
    done = subprocess.run([sys.executable, "-c", PROGRAM], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[:2] == ["went on", "raised again at the checkpoint"], done.stdout
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr, done.stderr


def test_other_unraisable_exceptions_are_still_printed():
    program = PROGRAM.replace("os.kill(os.getpid(), signal.SIGTERM)", "raise ValueError('mine')")
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=60)
    assert "ValueError: mine" in done.stderr and "raised again" not in done.stdout, done
