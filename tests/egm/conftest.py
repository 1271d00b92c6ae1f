"""Fixtures of the EGM tests: the fixed task's run folder, a server in a thread, a free port."""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import joulepath
from joulepath.optimize import OptimizeConfig, optimize_move, write_run

START = (0.3, 0.2, -0.4, 0.5, -0.6, 1.0)
END = (-0.9, 0.6, 0.3, -1.2, 0.8, -1.5)
DURATION = 1.6


@pytest.fixture(scope="session")
def egm_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The fixed task optimized with the default settings, written with ``export="egm"``."""
    robot = joulepath.load_robot("irb120")
    result = optimize_move(robot, np.array(START), np.array(END), DURATION, OptimizeConfig())
    out = tmp_path_factory.mktemp("egm_run")
    write_run(result, robot, out, export="egm")
    return out


def free_port() -> int:
    """An ephemeral UDP port of 127.0.0.1 that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class Background:
    """Run ``target`` in a thread; ``address`` is set once it listens, ``result``/``error`` when it ends."""

    def __init__(self, target: Callable[[Callable[[tuple[str, int]], None]], Any]) -> None:
        self.address: tuple[str, int] | None = None
        self.result: Any = None
        self.error: BaseException | None = None
        self._listening = threading.Event()

        def run() -> None:
            try:
                self.result = target(self._on_listening)
            except BaseException as err:  # handed to the test
                self.error = err
            finally:
                self._listening.set()

        self._thread = threading.Thread(target=run, daemon=True)
        self._thread.start()

    def _on_listening(self, address: tuple[str, int]) -> None:
        self.address = address
        self._listening.set()

    def wait_listening(self, timeout: float = 30.0) -> tuple[str, int]:
        assert self._listening.wait(timeout), "the server did not start listening"
        if self.error is not None:
            raise self.error
        assert self.address is not None
        return self.address

    def join(self, timeout: float = 60.0) -> None:
        self._thread.join(timeout)
        assert not self._thread.is_alive(), "the server did not stop"


@pytest.fixture
def background() -> Iterator[type[Background]]:
    yield Background
