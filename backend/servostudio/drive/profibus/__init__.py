"""The PROFIdrive-style parameter channel (PKW) and process data (PZD) of the TTA-PRO, seen from the master: the
client-side equivalent of the CANopen SDO client (docs/profibus.md §4-5). The wire framing is in
`servostudio.transport.profibus`.
"""
