"""Frequency response (Bode) of an axis from standard objects: multi-sine excitation by RPDO at the SYNC rate, the
response from the drive's recorder or synchronous TPDOs, averaged over periods, with coherence
(docs/frequency-response.md).
"""
