"""drive layer (see servostudio/__init__.py): talking to one drive through its dictionary.

- ``link``: one bus — reader thread, dispatch by COB-ID, reconnection;
- ``sdo`` / ``abort_codes``: the SDO client engine (one transfer per node, all nodes in parallel);
- ``access`` / ``values``: typed read/write checked against the dictionary before anything is sent;
- ``nmt``, ``cia402``, ``control``: NMT commands, CiA 402 states and commands, state control, fault reset;
- ``faults``, ``monitor``: fault decoding, EMCY / heartbeat / state events;
- ``profiles``: what differs between XtrapulsPac, CD1-k and encoTRive, keyed by semantic names.
See docs/drive-access.md.
"""
