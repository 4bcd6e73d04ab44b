"""Worker processes never outlive the program (bridge/workers.py).

A new user found the aero stage's two CFD workers and the resource tracker alive with parent PID 1 after
Ctrl-C (2 of 5 times) and after SIGTERM (every time), computing for nobody.  Every process the command
starts inherits its environment, so each run here carries a token of its own in it: after the command
has ended, no process on the machine may still hold that token.  Linux only (/proc).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="needs Linux's /proc")


def processes_with(token: str) -> list[int]:
    """PIDs of the live processes whose environment holds ``token`` (zombies have none)."""
    found = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                if token.encode() in (d / "environ").read_bytes():
                    found.append(int(d.name))
            except OSError:
                continue
    return found


def left_behind(token: str, wait_s: float = 15.0) -> list[str]:
    """The command lines of the token's processes still alive after ``wait_s`` (a worker may need a moment
    to see that its parent is gone)."""
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        if not processes_with(token):
            return []
        time.sleep(0.2)
    out = []
    for pid in processes_with(token):
        try:
            out.append(f"{pid}: " + (Path("/proc") / str(pid) / "cmdline").read_bytes().replace(b"\0", b" ").decode())
        except OSError:
            pass
    return out


def start(args: list[str], token: str, cwd: Path = REPO) -> tuple[subprocess.Popen, list[str]]:
    """Start ``python args`` with the token in its environment; its stderr lines collect in the list, read by
    ``proc.reader`` (a thread that ends when every process holding the pipe has closed it: the command, its
    workers and the resource tracker, whose warnings come last)."""
    env = {**os.environ, "BRIDGE_TEST_TOKEN": token}
    proc = subprocess.Popen([sys.executable, *args], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)   # its own process group
    lines: list[str] = []
    proc.reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
    proc.reader.start()
    return proc, lines


def all_output(proc: subprocess.Popen, lines: list[str], timeout: float = 30.0) -> str:
    """Everything the command and the processes it started wrote, once they have all closed the pipe (on a
    loaded machine the reader may lag behind the command's exit)."""
    proc.reader.join(timeout)
    assert not proc.reader.is_alive(), f"the output pipe is still open after {timeout} s: {''.join(lines)[-2000:]}"
    return "".join(lines)


def wait_for(lines: list[str], text: str, proc: subprocess.Popen, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while not any(text in line for line in lines):
        assert proc.poll() is None, f"ended ({proc.returncode}) before {text!r}: {''.join(lines)[-2000:]}"
        assert time.monotonic() < deadline, f"no {text!r} in {timeout} s: {''.join(lines)[-2000:]}"
        time.sleep(0.05)


# Two CFD cases side by side through the aero stage's own runner, long enough to be running when the
# parent is killed; "running" is printed once both workers have sent a progress line.
TWO_CASES = """
import sys
from bridge.aero.forced_motion import ForcedCase, run_cases
from bridge.aero.presets import preset
from bridge.cfd.sections import FlatPlate

def main():
    shape = [FlatPlate(1.0, 0.05).polygon()]
    jobs = [(ForcedCase.thesis(dof, 0.2), None, dof) for dof in ("heave", "pitch")]
    seen = set()
    def progress(line):
        seen.add(line.split(":")[0])
        if len(seen) == 2:
            print("running", flush=True)
    run_cases(shape, jobs, preset("tiny", "single"), progress=progress, workers=2)

if __name__ == "__main__":
    main()
"""


def test_workers_end_by_themselves_when_their_parent_is_killed(tmp_path):
    """SIGKILL leaves the parent no chance to clean up: the workers must notice and end on their own."""
    script = tmp_path / "two_cases.py"
    script.write_text(TWO_CASES)
    token = uuid.uuid4().hex
    proc, lines = start([str(script)], token)
    try:
        wait_for(lines, "running", proc)
        workers = [p for p in processes_with(token) if p != proc.pid]
        assert len(workers) >= 2, workers   # the two case workers (and the resource tracker)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
        assert left_behind(token) == []
    finally:
        for pid in processes_with(token):
            os.kill(pid, signal.SIGKILL)


@pytest.mark.slow   # ~70 s: six runs of the CFD chain, interrupted; runs in CI with -m slow
@pytest.mark.parametrize("signum, after, group, status", [
    (signal.SIGINT, "aero: ", False, 130),          # while the workers are being started
    (signal.SIGINT, "aero: ", True, 130),           # ... by a terminal's Ctrl-C, which every process gets
    (signal.SIGINT, "aero case", False, 130),       # while both compute
    (signal.SIGINT, "aero case", True, 130),
    (signal.SIGINT, "aero static", False, 130),     # later cases queued behind running ones
    (signal.SIGTERM, "aero case", False, 143),      # a batch system's or a CI time-out's stop
])
def test_an_interrupted_cfd_chain_leaves_no_worker(tmp_path, signum, after, group, status):
    token = uuid.uuid4().hex
    proc, lines = start(["-m", "bridge.scenario", "great_belt", "--stages", "aero", "--quality", "tiny",
                         "--out", str(tmp_path / "out")], token)
    try:
        wait_for(lines, after, proc)
        if group:
            os.killpg(proc.pid, signum)
        else:
            proc.send_signal(signum)
        assert proc.wait(timeout=60) == status, "".join(lines)[-2000:]
        assert left_behind(token) == []
        output = all_output(proc, lines)
        last = output.strip().splitlines()[-1]
        assert last.startswith("interrupted" if signum == signal.SIGINT else "terminated"), output[-2000:]
        assert "Traceback" not in output and "leaked" not in output
    finally:
        for pid in processes_with(token):
            os.kill(pid, signal.SIGKILL)


def test_ctrl_c_reaching_another_thread_still_waits_for_a_held_block():
    """bridge.interrupts.sigint_held: a SIGINT that the kernel hands to another thread (a pool's manager or a
    queue's feeder thread) still only flags it for the main thread's Python handler, which used to raise
    KeyboardInterrupt inside the held block whatever the main thread's mask: a worker started there was left
    without its start-up data and printed "EOFError: Ran out of input" (seen in the slow interrupt test)."""
    from bridge.interrupts import sigint_held

    go, sent = threading.Event(), threading.Event()

    def send() -> None:   # started before the block, so it does not block SIGINT: the kernel delivers it here
        go.wait(5)
        os.kill(os.getpid(), signal.SIGINT)
        sent.set()

    sender = threading.Thread(target=send)
    sender.start()
    finished = False
    with pytest.raises(KeyboardInterrupt):
        with sigint_held():
            go.set()
            sent.wait(5)
            for _ in range(200):   # many bytecodes: the handler would have run by now
                time.sleep(0.001)
            finished = True
    sender.join()
    assert finished and sent.is_set()


def test_a_stopped_pool_has_ended_its_manager_thread_when_the_interrupt_leaves_it():
    """bridge.workers.worker_pool, interrupted: its first shutdown (wait=False, to cancel the queued cases)
    made the pool forget its manager thread, so the second one did not wait for it.  The thread's end frees
    the pool's queues and unlinks their semaphores; cut off by the program's hard exit half-way, it left the
    resource tracker to print "leaked semaphore" warnings after "interrupted" (the slow interrupt test, about
    one run in ten).  Now the thread has ended before the interrupt leaves the pool."""
    import multiprocessing

    from bridge.workers import worker_pool

    managers = []
    with pytest.raises(KeyboardInterrupt):
        with worker_pool(1, multiprocessing.get_context("spawn"), grace_s=0.5) as pool:
            pool.submit(time.sleep, 30)   # a case running when the interrupt lands
            pool.submit(time.sleep, 30)   # and one queued behind it
            managers.append(pool._executor_manager_thread)
            raise KeyboardInterrupt
    assert managers[0] is not None and not managers[0].is_alive()
