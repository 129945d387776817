"""Jobs run as local child processes, as many at once as the worker count and the memory allow.

Each job reserves the memory its panorama needs at its peak (`memory.required_bytes`); a job
starts when a worker is free and its reservation fits what is left of the budget, or when
nothing else runs (a job larger than the whole budget then runs alone and its own check
refuses it with the message a single run gives). Jobs start in the file's order.
"""
from __future__ import annotations

import threading
from collections.abc import Callable, Sequence

from .execute import Record, Task, pending, run_job


def run_local(tasks: Sequence[Task], needs: Sequence[int], *, workers: int, budget: int | None,
              on_done: Callable[[Record], None], runner: Callable[..., Record] = run_job) -> None:
    """Run `tasks` (task i reserving `needs[i]` bytes of `budget`; None: no limit) on at most
    `workers` threads, each waiting on its child; `on_done` gets every record on the calling
    thread. Ctrl-C stops the children in flight, records them as cancelled, then re-raises."""
    finished: list[Record] = []
    changed = threading.Condition()
    cancel = threading.Event()
    state = {"running": 0, "reserved": 0}

    def work(task: Task, need: int) -> None:
        try:
            record = runner(task, cancel)
        except Exception as error:  # a bug or a full disk in the runner must not hang the batch
            record = pending(task.job, "failed", f"the batch could not run the job: {error}")
        with changed:
            state["running"] -= 1
            state["reserved"] -= need
            finished.append(record)
            changed.notify_all()

    def fits(need: int) -> bool:
        if state["running"] >= workers:
            return False
        return state["running"] == 0 or budget is None or state["reserved"] + need <= budget

    def hand_over() -> None:
        while finished:
            on_done(finished.pop(0))

    threads = []
    try:
        for task, need in zip(tasks, needs, strict=True):
            with changed:
                while not fits(need):
                    changed.wait(0.5)
                    hand_over()
                state["running"] += 1
                state["reserved"] += need
            thread = threading.Thread(target=work, args=(task, need), name=f"dimred-job-{task.job.id}", daemon=True)
            thread.start()
            threads.append(thread)
        with changed:
            while state["running"]:
                changed.wait(0.5)
                hand_over()
            hand_over()
    except KeyboardInterrupt:
        cancel.set()
        for thread in threads:
            thread.join()
        hand_over()
        raise
