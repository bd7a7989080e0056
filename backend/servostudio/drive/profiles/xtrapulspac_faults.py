"""XtrapulsPac errors (0x3022,1/2) and warnings (0x3024): name, CiA 402 code and the manual's troubleshooting text.

Source: XtrapulsPac user guide §3.6–3.7 (seed 000, L3496–4013 troubleshooting, L4277–4359 code mapping,
L4360–4409 warnings).  Error code = bit number + 1 over the 64-bit pair 0x3022,1 (codes 1–32) and 0x3022,2
(codes 33–64); the EMCY frame carries it in byte 3.  An empty remedy means the manual gives none.
"""

from __future__ import annotations

from servostudio.drive.faults import FaultInfo

_EMC = (
    "Check that the DNC/PLC-amplifier-motor ground connections and shield answer the Installation manual "
    "requirements. Check the application EMC disturbances level."
)
_REPHASE = (
    " In the incremental encoder configuration without HES, execute the motor phasing procedure again after "
    "the fault is released."
)
_POWER_CYCLE = (
    "Switch the 24 V logic supply off and on again. If the error cannot be reset, the amplifier is out of order."
)

ERRORS: dict[int, FaultInfo] = {
    info.code: info
    for info in (
        FaultInfo(1, 0x5080, "Hardware System 2 error", _EMC),
        FaultInfo(
            2,
            0x5112,
            "24 V error",
            "Check that the logic supply voltage is within the specified range. Check its "
            "waveform (ripple, overvoltage and undervoltage spikes).",
        ),
        FaultInfo(3, 0x3220, "Undervoltage (temporized)", "Check that the power supply is actually on."),
        FaultInfo(
            4,
            0x7110,
            "Braking system error",
            "Check the presence of the internal resistor jumper or of the "
            "external resistor, and that the external resistor is not broken (open circuit). If the error cannot "
            "be reset, the braking system is out of order (transistor in short circuit).",
        ),
        FaultInfo(
            5,
            0x9082,
            "Safety channel 2 (STO2) error",
            "Check the STO2 input state with regard to the STO1 input "
            "state. Once the STO fault is released, the drive must be switched off to cancel the fault.",
        ),
        FaultInfo(
            6,
            0x3210,
            "Overvoltage",
            "At start: check the AC supply voltage. During operation: check the DC bus "
            "voltage during decelerations and the sizing of the braking resistor for the deceleration phases.",
        ),
        FaultInfo(7, 0x6182, "Internal communication 2 error", _EMC),
        FaultInfo(
            8,
            0x2230,
            "IGBT module",
            "Check for a short circuit in the motor wiring, at the motor terminals, and "
            "between a motor phase and ground. Check the Rated current setting against the amplifier "
            "specification, the amplifier maximum temperature, and that the fan works.",
        ),
        FaultInfo(9, 0x3130, "Main phase error", ""),
        FaultInfo(10, 0x3130, "Mains phase loss", ""),
        FaultInfo(
            11,
            0x4210,
            "Power module over-temperature",
            "Check the Rated current setting against the amplifier "
            "specification, that the amplifier maximum temperature specification is met, and that the fan works.",
        ),
        FaultInfo(12, 0x4210, "Power module over-temperature (some models)", "As error 11."),
        FaultInfo(
            13,
            0x5090,
            "Fan",
            "Only on some drive models. Check that the fan blades are not blocked by a foreign "
            "body and that the fan rotor is not locked.",
        ),
        FaultInfo(14, 0x1000, "Reserved", ""),
        FaultInfo(15, 0x1000, "Reserved", ""),
        FaultInfo(16, 0x1000, "Reserved", ""),
        FaultInfo(
            17,
            0x5210,
            "Current measurement offset",
            "Check that the motor is not driven by the mechanical load. "
            "If the error cannot be reset, the amplifier current sensors are out of order.",
        ),
        FaultInfo(18, 0x2310, "Overcurrent", "Check the current loop adjustment with regard to the motor inductance."),
        FaultInfo(
            19,
            0x7305,
            "Encoder 1 counting error / HES counting error",
            "Check that the encoder maximum pulse "
            "frequency at maximum motor speed fulfils the encoder specification and that the encoder wiring follows "
            "the shield recommendations. HES-only feedback: check the HES wiring and supply, and increase the Motor "
            "HES error threshold if necessary." + _REPHASE,
        ),
        FaultInfo(
            20,
            0x7303,
            "Resolver tracking error",
            "At start: check the resolver type against the amplifier "
            "specification. During operation: check that the resolver wiring follows the shield recommendations.",
        ),
        FaultInfo(
            21,
            0x7303,
            "Resolver cable interrupted",
            "Check the resolver connection on the amplifier connector, "
            "the resolver type, and the cable wiring between resolver and amplifier.",
        ),
        FaultInfo(
            22,
            0x7305,
            "Encoder 1 cable interrupted",
            "Check the encoder supply connection and the A and B channel "
            "connections on the amplifier connector." + _REPHASE,
        ),
        FaultInfo(
            23,
            0x7305,
            "Encoder 1 Z marker",
            "Check the marker pulse connection. If the encoder has no marker "
            "channel, disable the protection by setting Zero mark pitch to 0. Check the Motor encoder resolution "
            "and Zero mark pitch values." + _REPHASE,
        ),
        FaultInfo(24, 0x1000, "Encoder 2 link", "Check the encoder connection on the amplifier connector."),
        FaultInfo(
            25,
            0x1000,
            "Sensorless error",
            "Check that Motor EMF error threshold is greater than the sensorless "
            "Low speed threshold, and that the Motor EMF constant is correct.",
        ),
        FaultInfo(
            26,
            0x1000,
            "Ambient temperature",
            "Check the amplifier operating temperature specification, its "
            "cooling system, and the Rated current setting against the amplifier specification.",
        ),
        FaultInfo(27, 0x7120, "Motor brake", ""),
        FaultInfo(28, 0xFF80, "Power stage controller error", "Generic fault of the amplifier power stage."),
        FaultInfo(29, 0x50A1, "Manufacturer parameters error", _POWER_CYCLE),
        FaultInfo(30, 0x6181, "Internal communication 1 error", _EMC),
        FaultInfo(31, 0x6320, "Configuration error", ""),
        FaultInfo(32, 0x50A0, "System error", _POWER_CYCLE),
        FaultInfo(33, 0x8300, "Reserved (torque control)", ""),
        FaultInfo(
            34,
            0x8400,
            "Speed following error",
            "Check that the load suits the motor and amplifier ratings, that "
            "the axis is not on a mechanical limit, the motor voltage limit against the maximum speed set point, "
            "the accelerations, and the speed loop adjustment. Increase Speed following error threshold (0x306D) "
            "if the motion cycle needs it.",
        ),
        FaultInfo(
            35,
            0x8611,
            "Position following error",
            "Check that the load suits the motor and amplifier ratings, "
            "that the axis is not on a mechanical limit, the motor voltage limit against the maximum speed set "
            "point, the accelerations, and the position loop adjustment. Increase Following error threshold "
            "(0x6065) if the motion cycle needs it.",
        ),
        FaultInfo(36, 0x8680, "Software position limit", ""),
        FaultInfo(
            37,
            0x4290,
            "Motor temperature error",
            "At start: check the thermal sensor type (NTC or PTC) and its "
            "connection to the amplifier. During operation: find the cause of the overheating (shaft overload, "
            "duty cycle too high, motor too small for the machine cycle).",
        ),
        FaultInfo(38, 0x2350, "I²t error", "Check the amplifier current cycle with regard to the Rated current value."),
        FaultInfo(39, 0x6190, "System parameters error", ""),
        FaultInfo(40, 0xFFA0, "Busy / operation timeout", ""),
        FaultInfo(
            41,
            0x6320,
            "Calibration parameters file error",
            "If the firmware was downgraded, reload the correct "
            "firmware. If the error remains after switching the amplifier off and on, it is out of order.",
        ),
        FaultInfo(
            42,
            0x6320,
            "Drive parameters file error",
            "After a firmware upgrade, save the parameters to flash "
            "(new parameters get their defaults in DRIVEPAR.TXT). After a downgrade, saving loses parameters: "
            "reload the correct firmware instead.",
        ),
        FaultInfo(
            43,
            0x6320,
            "User parameters or template file error",
            "Edit and check the user parameter file: some "
            "objects are not compatible with the amplifier firmware version.",
        ),
        FaultInfo(
            44,
            0x6320,
            "Sequence file error",
            "Check the sequence file: some parameters are not compatible with the amplifier firmware version.",
        ),
        FaultInfo(45, 0x6320, "Cam file error", ""),
        FaultInfo(46, 0x8181, "Extension error or fieldbus watchdog error", ""),
        FaultInfo(47, 0x50B2, "Extension error or fieldbus hardware error", ""),
        FaultInfo(48, 0x50B3, "Extension error or fieldbus hardware error", ""),
        FaultInfo(
            49,
            0x8780,
            "Fieldbus SYNC cycle error",
            "Check the fieldbus cycle period (0x1006) and the SYNC timing: "
            "jitter of half a period or more, or a period accuracy outside 0.4 %, raise this error.",
        ),
        FaultInfo(
            50,
            0x8782,
            "Fieldbus IP reference underflow/overflow",
            "Check that the IP reference (0x60C1,1) is "
            "mapped in an RPDO sent every bus cycle, at least 100 µs before the SYNC.",
        ),
        FaultInfo(
            51,
            0x8130,
            "Fieldbus guarding error",
            "CANopen node guarding or heartbeat error: check the bus, the master and the guarding/heartbeat settings.",
        ),
        FaultInfo(52, 0x1000, "Reserved", ""),
        FaultInfo(53, 0x7600, "SD card error", "See the SD card chapter of the manual."),
        FaultInfo(54, 0x6320, "File erase/write error", "Renew the file transfer."),
        FaultInfo(55, 0x5220, "Watchdog error", ""),
        FaultInfo(
            56,
            0x9081,
            "Safety channel 1 (STO1) error",
            "Check the STO1 input state with regard to the STO2 input "
            "state. Once the STO fault is released, the drive must be switched off to cancel the fault.",
        ),
        FaultInfo(57, 0x6282, "User program error", ""),
        FaultInfo(58, 0x7580, "CAN extension module communication lost or not found", ""),
        FaultInfo(59, 0x1000, "Encoder 2 absolute error", ""),
        FaultInfo(
            60,
            0xFF10,
            "Stop operation failed or speed/position monitoring failed",
            "Check the stop and monitoring parameters.",
        ),
        FaultInfo(
            61,
            0x7305,
            "Encoder 1 commutation channel / incremental channel error",
            "Incremental encoder + HES: "
            "check the HES supply and wiring, toggle Reverse HES track if wrong, check Motor encoder resolution. "
            "Hiperface: toggle Reverse incremental track if wrong, check the SinCos and data channel wiring. "
            "SinCos with CD tracks: check the supply, the CD channel wiring and waveforms, toggle Reverse CD track "
            "if "
            "wrong, check Motor encoder resolution. In every case check grounding and shielding.",
        ),
        FaultInfo(
            62,
            0x7305,
            "Encoder 1 absolute channel error",
            "Check the encoder supply voltage, the data channel "
            "wiring, and the grounding and shielding of the encoder cable.",
        ),
        FaultInfo(63, 0x6280, "User program execution error", ""),
        FaultInfo(
            64,
            0xFFA2,
            "Procedure error (auto-tuning, auto-phasing…)",
            "The procedure failed because of an "
            "external cause and the calculated parameters are wrong. Check that the limit switch inputs are not "
            "active and that the motor is unloaded and its shaft free during the procedure.",
        ),
    )
}

WARNINGS: dict[int, FaultInfo] = {
    info.code: info
    for info in (
        FaultInfo(1, 0, "STO active", ""),
        FaultInfo(9, 0, "Cogging torque", ""),
        FaultInfo(10, 0, "Mains phase loss", ""),
        FaultInfo(11, 0, "IGBT module temperature", ""),
        FaultInfo(13, 0, "Fan", ""),
        FaultInfo(14, 0, "Daughter board/plugin software incompatible", ""),
        FaultInfo(15, 0, "Daughter board/plugin hardware not ready", ""),
        FaultInfo(16, 0, "Daughter board/plugin software not ready", ""),
        FaultInfo(17, 0, "Limit switch", ""),
        FaultInfo(18, 0, "Ambient temperature", ""),
        FaultInfo(19, 0, "I²t", ""),
        FaultInfo(20, 0, "Undervoltage (DC bus below 0x3079)", ""),
        FaultInfo(21, 0, "SoftStart forced", ""),
        FaultInfo(22, 0, "Motor temperature", ""),
        FaultInfo(25, 0, "Position limit", ""),
        FaultInfo(26, 0, "CAN extension module communication lost/not found", ""),
        FaultInfo(27, 0, "Encoder 2 multi-turn absolute init/overflow", ""),
        FaultInfo(29, 0, "Encoder 1 multi-turn absolute init/overflow", ""),
        FaultInfo(30, 0, "Cannot read/write to encoder", ""),
        FaultInfo(31, 0, "Motor phasing init not OK", "Execute the motor phasing procedure."),
    )
}
