"""PROFIBUS-DP wire format: FDL telegrams (IEC 61158 type 3 / EN 50170), DP-V0 service payloads and the PPO
configurations of PROFIdrive-style drives. The single definition of the bytes on the line: the simulated DP slave
imports it, and so will the master transport (docs/profibus.md §3).
"""
