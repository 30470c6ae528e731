"""What the command-line tests share: running `aolab` as a user does and reading its one-line
errors as a terminal shows them."""
import subprocess
import sys

from aolab import cli


def status_of(argv) -> int:
    """cli.main's exit status, argparse's SystemExit included."""
    try:
        return cli.main(argv)
    except SystemExit as e:
        return e.code


def aolab_cmd(*args, timeout=120):
    """`aolab *args` in a child process, as a user runs it (its output captured)."""
    return subprocess.run([sys.executable, "-m", "aolab", *args], capture_output=True,
                          text=True, timeout=timeout)


def terminal_lines(text: str) -> list[str]:
    """Lines as a terminal shows them: split at newlines only. str.splitlines() also splits
    at \x1c-\x1e, \x85 and \u2028, which a user's argument may hold (hypothesis found
    '\x1e0') and which argparse echoes inside its one-line message."""
    return text.strip().split("\n")


def assert_one_error_line(err: str, *parts: str) -> None:
    """``err`` is one line `aolab: ...` holding every one of ``parts``."""
    lines = terminal_lines(err)
    assert len(lines) == 1 and lines[0].startswith("aolab: "), err
    for part in parts:
        assert part in lines[0], err
