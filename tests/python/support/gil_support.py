"""The check that a call releases the GIL: how often the main thread ran while it did."""
import threading


def ticks_while(work) -> int:
    """Runs `work()` in another thread and counts the main thread's 1-ms waits until it is
    done: a handful or more means the main thread ran meanwhile (the GIL was released)."""
    done = threading.Event()
    ticks = 0

    def run():
        work()
        done.set()

    t = threading.Thread(target=run)
    t.start()
    while not done.is_set():
        ticks += 1
        done.wait(0.001)
    t.join()
    return ticks
