"""transport layer (see servostudio/__init__.py): buses named by spec strings.

- ``spec``: ``socketcan:can0``, ``serial:/dev/ttyUSB0@19200``, ``sim`` … → ``BusSpec`` (docs/drive-access.md);
- ``open``: a python-can bus for a spec;
- ``rs232_framing`` / ``rs232``: the XtrapulsPac 12-byte serial frames and the python-can plugin
  ``servostudio_rs232`` with SDO redirection (docs/rs232-link.md);
- ``socketcand``: a socketcand client that notices a lost connection.
"""
