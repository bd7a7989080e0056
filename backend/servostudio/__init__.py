"""Servo Studio: browser-based commissioning tool for CANopen servo drives.

Layers, from the wire up (each imports only the layers below it):

- ``transport``  buses and serial framing (python-can plugins, bus spec strings)
- ``od``         object dictionaries: CiA 306 EDS plus companion properties
- ``formats``    the drives' own files: DRIVEPAR.TXT / USER_PAR.TXT, SEQUENCE.TXT
- ``drive``      SDO access, CiA 402, device profiles
- ``services``   buses, scan, backup/restore, dialog terminal, projects
- ``api``        FastAPI routers (REST, WebSocket); ``cli`` is the command line

``sim`` is a separate package: simulated drives that speak only CAN frames. docs/architecture.md states which
layer may import which; tests/test_architecture.py holds the code to it.
"""

__version__ = "0.1.0"
