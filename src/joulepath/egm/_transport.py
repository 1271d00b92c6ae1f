"""Transport layer: a UDP socket with timeouts, nothing else (no parsing, no policy)."""

from __future__ import annotations

import socket
import time
from dataclasses import dataclass
from types import TracebackType

from joulepath.egm._protocol import MAX_DATAGRAM
from joulepath.errors import InvalidInput

Address = tuple[str, int]


@dataclass(frozen=True, slots=True)
class Datagram:
    """What arrived: the payload, the sender, and the PC's monotonic clock at arrival (s)."""

    data: bytes
    sender: Address
    received_s: float


class UdpEndpoint:
    """A bound UDP socket: :meth:`receive` with a timeout, :meth:`send` to an address.

    ``port`` 0 binds an ephemeral port (:attr:`address` tells which). Use as a
    context manager, or call :meth:`close`.

    Raises
    ------
    InvalidInput
        The address cannot be bound (in use, not an address of this machine).
    """

    def __init__(self, host: str, port: int) -> None:
        self.refused = 0
        """ICMP "port unreachable" reports seen (a connected peer that closed its port)."""
        self._peer: Address | None = None
        if not 0 <= port <= 65535:
            raise InvalidInput(f"port must be 0..65535, got {port}")
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._sock.bind((host, port))
        except OSError as err:
            self._sock.close()
            raise InvalidInput(
                f"cannot listen on UDP {host}:{port} ({err.strerror or err}); choose a free port "
                "and an address of this machine"
            ) from err

    @property
    def address(self) -> Address:
        """The bound (host, port)."""
        host, port = self._sock.getsockname()[:2]
        return str(host), int(port)

    def receive(self, timeout_s: float, *, stop_on_refused: bool = False) -> Datagram | None:
        """The next datagram, or None when none arrives within ``timeout_s`` seconds.

        An ICMP "port unreachable" for an earlier send is counted in :attr:`refused`;
        with ``stop_on_refused`` it also ends the wait (None), else the wait goes on.
        """
        deadline = time.monotonic() + timeout_s
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            self._sock.settimeout(left)
            try:
                data, sender = self._sock.recvfrom(MAX_DATAGRAM)
            except TimeoutError:
                return None
            except (ConnectionResetError, ConnectionRefusedError):
                self.refused += 1
                if stop_on_refused:
                    return None
                continue
            return Datagram(data=data, sender=(str(sender[0]), int(sender[1])), received_s=time.monotonic())

    def connect(self, address: Address) -> None:
        """Talk to ``address`` only: datagrams from elsewhere are dropped by the system, and a
        closed port there shows as :attr:`refused` (the ICMP reports reach connected sockets)."""
        self._sock.connect(address)
        self._peer = address

    def send(self, data: bytes, address: Address) -> None:
        """Send one datagram to ``address`` (a connected socket's refused send counts in :attr:`refused`)."""
        try:
            if address == self._peer:
                self._sock.send(data)
            else:
                self._sock.sendto(data, address)
        except (ConnectionRefusedError, ConnectionResetError):
            self.refused += 1

    def close(self) -> None:
        """Release the socket."""
        self._sock.close()

    def __enter__(self) -> UdpEndpoint:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
