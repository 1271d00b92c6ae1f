"""Transport layer: a real UDP socket pair on 127.0.0.1, timeouts, refusals."""

import time

import pytest

from joulepath.egm import UdpEndpoint
from joulepath.errors import InvalidInput


def test_udp_endpoint_sends_and_receives_on_loopback():
    with UdpEndpoint("127.0.0.1", 0) as a, UdpEndpoint("127.0.0.1", 0) as b:
        a.send(b"hello", b.address)
        got = b.receive(2.0)
        assert got is not None
        assert got.data == b"hello"
        assert got.sender == a.address


def test_udp_endpoint_receive_times_out():
    with UdpEndpoint("127.0.0.1", 0) as a:
        t0 = time.monotonic()
        assert a.receive(0.05) is None
        assert 0.04 <= time.monotonic() - t0 < 1.0


def test_udp_endpoint_refuses_a_port_in_use():
    with UdpEndpoint("127.0.0.1", 0) as a:
        with pytest.raises(InvalidInput, match="cannot listen"):
            UdpEndpoint("127.0.0.1", a.address[1])


def test_udp_endpoint_refuses_a_bad_port():
    with pytest.raises(InvalidInput, match="port"):
        UdpEndpoint("127.0.0.1", 70000)
