"""Ctrl-C held while workers start: noted, then raised once the cluster or pool is whole.

These checks run in a fresh interpreter so that the signal handling of the test process is
left alone.
"""

import subprocess
import sys
import textwrap

from tests.conftest import default_sigint

SCRIPT = textwrap.dedent(
    """
    import os, signal, threading, time
    from poro2d.worker_signals import hold_interrupts, release_interrupts

    before = signal.getsignal(signal.SIGINT)  # default_int_handler, or SIG_IGN under a runner that ignores it
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)  # another thread of the command (numba's, the display's)
    other.start()
    held = hold_interrupts()
    os.kill(os.getpid(), signal.SIGINT)  # a Ctrl-C while the workers start
    time.sleep(0.1)
    print("held")
    try:
        release_interrupts(held)
        time.sleep(0.1)
        print("lost")
    except KeyboardInterrupt:
        print("raised at release")
    release_interrupts(held)  # a second release (an error path) changes nothing
    print("handler", signal.getsignal(signal.SIGINT) is before)
    quiet = hold_interrupts()
    release_interrupts(quiet)
    print("quiet release")
    stop.set()
    """
)


def test_interrupt_during_the_hold_is_raised_at_the_release(tmp_path):
    script = tmp_path / "hold.py"
    script.write_text(SCRIPT)
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=120, preexec_fn=default_sigint
    )
    assert done.returncode == 0, done.stderr
    expected = ["held", "raised at release", "handler True", "quiet release"]
    assert done.stdout.splitlines() == expected, done.stdout


def test_release_of_nothing_held_is_harmless():
    from poro2d.worker_signals import release_interrupts

    release_interrupts(None)


CHILD = textwrap.dedent(
    """
    import multiprocessing as mp, signal
    import poro2d.cli  # the command's main module imports this first, as poro2d's does

    def report(queue):
        queue.put(signal.getsignal(signal.SIGINT) == signal.SIG_IGN)

    if __name__ == "__main__":
        ctx = mp.get_context("spawn")
        queue = ctx.Queue()
        child = ctx.Process(target=report, args=(queue,))
        child.start()
        print("child ignores", queue.get(timeout=60))
        child.join()
        print("command ignores", signal.getsignal(signal.SIGINT) == signal.SIG_IGN)
    """
)


def test_a_spawned_child_of_the_command_ignores_interrupts_from_its_first_import(tmp_path):
    script = tmp_path / "command.py"
    script.write_text(CHILD)
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=120, preexec_fn=default_sigint
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["child ignores True", "command ignores False"], done.stdout
