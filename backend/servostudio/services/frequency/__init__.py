"""Frequency response (Bode) of an axis from standard objects: multi-sine excitation by RPDO at the SYNC rate, the
response from the drive's recorder, or from synchronous TPDOs answered to the same SYNCs on a drive without one
(``tpdo_source``), averaged over periods, with coherence (docs/frequency-response.md).
"""
