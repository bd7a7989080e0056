"""Frequency response (Bode) of an axis from standard objects: multi-sine excitation by RPDO at the SYNC rate, the
response from the drive's recorder (synchronous TPDOs for drives without one: not built yet), averaged over
periods, with coherence (docs/frequency-response.md).
"""
