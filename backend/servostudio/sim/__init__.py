"""Simulated CANopen drives (docs/simulator.md): a separate package that speaks only CAN frames.

Entry points: `servostudio.sim.network.SimulatedNetwork` (drives + clock + bus; `open_bus()` for in-process
python-can/canopen clients), `servostudio.sim.socketcand.SocketcandServer`, `servostudio.sim.serial_link`
(RS-232 link over TCP or a pseudo-terminal) and what the `servostudio sim` command (`servostudio.cli.sim`) starts.
"""
