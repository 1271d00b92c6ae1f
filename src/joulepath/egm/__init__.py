"""Stream a run's path to an ABB controller through Externally Guided Motion (EGM), the PC side.

Three layers, each testable alone (STYLE.md §15):

* transport — :class:`UdpEndpoint`, a UDP socket with timeouts;
* protocol — :func:`decode_robot` / :func:`encode_sensor`: bytes ↔ typed messages of
  ABB's ``egm.proto`` (through ``abb-robot-client``'s ``egm_pb2``), validated;
* policy — :func:`step`, a pure function of the plan, the robot's reported state and
  the controller's time to the reference to send.

:func:`stream_run` puts them together for a run folder (``joulepath stream``) and
writes ``stream.csv`` and ``stream.json``; :func:`run_emulator` plays the controller's
side on 127.0.0.1 for tests and benchmarks.
"""

from joulepath.egm._emulator import GARBAGE, LOOPBACK, EmulatorConfig, EmulatorLog, run_emulator
from joulepath.egm._plan import (
    PLAN_FILES,
    RESULT_FILE,
    Plan,
    check_plan,
    hermite5,
    plan_file,
    read_plan,
    read_run_result,
    run_robot,
)
from joulepath.egm._policy import Phase, PolicyState, Reference, RobotState, StreamSettings, step
from joulepath.egm._protocol import (
    RobotMessage,
    SensorMessage,
    decode_robot,
    decode_sensor,
    egm_pb2,
    encode_robot,
    encode_sensor,
)
from joulepath.egm._server import (
    CONTROL_PERIOD,
    STREAM_CSV,
    STREAM_FILES,
    STREAM_JSON,
    Repetition,
    ServeConfig,
    Session,
    StreamOutcome,
    executed_energy,
    serve,
    stream_csv,
    stream_run,
    summarize,
)
from joulepath.egm._transport import Address, Datagram, UdpEndpoint

__all__ = [
    "Address",
    "CONTROL_PERIOD",
    "Datagram",
    "EmulatorConfig",
    "EmulatorLog",
    "GARBAGE",
    "LOOPBACK",
    "PLAN_FILES",
    "Phase",
    "Plan",
    "PolicyState",
    "RESULT_FILE",
    "Reference",
    "Repetition",
    "RobotMessage",
    "RobotState",
    "STREAM_CSV",
    "STREAM_FILES",
    "STREAM_JSON",
    "SensorMessage",
    "ServeConfig",
    "Session",
    "StreamOutcome",
    "StreamSettings",
    "UdpEndpoint",
    "check_plan",
    "decode_robot",
    "decode_sensor",
    "egm_pb2",
    "encode_robot",
    "encode_sensor",
    "executed_energy",
    "hermite5",
    "plan_file",
    "read_plan",
    "read_run_result",
    "run_emulator",
    "run_robot",
    "serve",
    "step",
    "stream_csv",
    "stream_run",
    "summarize",
]
