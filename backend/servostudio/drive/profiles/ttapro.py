"""Transtechnik TTA-PRO (Infranor-built positioner) on PROFIBUS-DP: its PNUs by the semantic names the CANopen
drives use where the TTA-PRO has the quantity, so services never see a PNU (docs/profibus.md §9).

Source: *TTA-PRO Profibus Communication Profile*, Issue 1.4 (the parameter list `eds/ttapro.pnu`, extraction in
`shared/spec/ttapro-profibus.md`). Addresses are (PNU, IND). Names whose CANopen meaning differs in unit or value
are not reused: the speed and current monitors are shares of the maximum speed and of the drive rating, not CiA 402
velocity and current (`speed_monitor`, `current_monitor`), the positioner mode (PNU 720) is no 0x6060 mode and the
homing configuration (766) no 0x6098 method. The status and control words are PZD1 words, not parameters: the
parameter list holds them at addresses beyond every PNU (`od.pnu_model.CONTROL_WORD`, `STATUS_WORD`) and the PKW
engine carries them through PZD. Their bits 0-3 and 7 (status bits 0-6) are CiA 402's, so `statusword` and
`controlword` name them and the CiA 402 state control and the motion guard work unchanged (docs/profibus.md §12).
"""

from __future__ import annotations

from servostudio.drive.profibus.pzd import ControlBit, StatusBit
from servostudio.drive.profiles.base import Addressing, DeviceProfile, ManualMotions, ProcedureAfterChange
from servostudio.drive.profiles.sequence_buffer import SequenceBuffer
from servostudio.drive.profiles.ttapro_faults import (
    ERRORS,
    POSITIONER_ERRORS_FIRST,
    POWER_STAGE_CODE,
    POWER_STAGE_FIRST,
    WARNINGS,
)
from servostudio.drive.profiles.ttapro_homing import HOMING_CONFIGURATIONS
from servostudio.od.model import SaveType
from servostudio.od.pnu_model import CONTROL_WORD, POSITION_SET_POINT, STATUS_WORD

PROFIBUS_DP = "PROFIBUS-DP"
QUICK_STOP = 0x0002
"""CiA 402's quick-stop command (`drive.cia402.Command.QUICK_STOP`)."""
PARAMETER_FILE = "TTAPAR.TXT"
"""The backup of the E parameters (saved by PNU 729), docs/profibus.md §10."""

_OBJECTS: dict[str, tuple[int, int]] = {
    # motor and commissioning
    "pole_pairs": (700, 0),
    "phase_order": (701, 0),
    "sensor_offset": (702, 0),
    "auto_phasing": (704, 0),
    "stop_current_share": (705, 0),
    "dc_bus_voltage": (706, 0),
    # current limits (shares of the drive rating, as the CD1-k's)
    "max_current_share": (710, 0),
    "rated_current_share": (711, 0),
    "current_limitation": (713, 0),
    "drive_rating": (715, 0),
    # current loop
    "kp_current_d": (716, 0),
    "ki_current_d": (717, 0),
    "kp_current_q": (718, 0),
    "ki_current_q": (719, 0),
    # modes, speed, brake, saving
    "positioner_mode": (720, 0),
    "max_motor_speed": (721, 0),
    "speed_ramp": (723, 0),
    "brake_on_delay": (726, 0),
    "brake_off_delay": (727, 0),
    "manual_brake": (728, 0),
    "save_parameters": (729, 0),
    # speed and position loop gains
    "kp_speed": (730, 0),
    "ki_speed": (731, 0),
    "kp_position": (732, 0),
    "kf_position": (733, 0),
    "current_filter": (734, 0),
    "anti_resonance_filter": (735, 0),
    "auto_tuning": (736, 0),
    "ka_position": (737, 0),
    "kf2_position": (738, 0),
    "kc_speed": (739, 0),
    "kd_speed": (830, 0),
    "kd_speed_filter": (831, 0),
    "speed_gain_scaling": (832, 0),
    # position
    "position_resolution": (740, 0),
    "encoder_increments": (870, 0),  # the resolution in its double form: position units per revolution
    "following_error_window": (741, 0),
    "positioner_configuration": (742, 0),
    "software_position_limit_max": (747, 0),
    "software_position_limit_min": (748, 0),
    "following_error_actual": (749, 0),
    "position_window": (757, 0),
    "profile_velocity": (760, 0),
    "profile_acceleration": (761, 0),
    "profile_deceleration": (762, 0),
    "jog_speed": (763, 0),
    "jog_acceleration": (764, 0),
    "jog_deceleration": (765, 0),
    "homing_configuration": (766, 0),
    "target_position": (767, 0),
    "home_offset": (768, 0),
    "position_actual": (774, 0),
    # feedback (PNU 894 programs the motor feedback from them)
    "encoder_input_selection": (890, 0),
    "encoder_input_resolution": (891, 0),
    "encoder_interpolation": (892, 0),
    "motor_feedback_selection": (893, 0),
    "sincos_feedback_tracks": (898, 0),
    "motor_feedback_programming": (894, 0),
    # monitors, versions, faults
    "drive_error_code": (755, 0),
    "digital_inputs": (769, 0),
    "software_version": (770, 0),
    "profibus_software_version": (771, 0),
    "positioner_error_code": (773, 0),
    "resolver_position": (775, 0),
    "speed_monitor": (776, 0),
    "current_monitor": (777, 0),
    "power_stage_fault_code": (778, 0),
    "warning_code": (873, 0),
    # the sequence table: procedures between the EEPROM and the buffer, and the buffer's fields
    "sequence_read": (780, 0),
    "sequence_write": (781, 0),
    "sequence_control": (782, 0),
    "sequence_position": (783, 0),
    "sequence_speed": (784, 0),
    "sequence_acceleration": (785, 0),
    "sequence_deceleration": (786, 0),
    "sequence_time": (787, 0),
    "sequence_link": (788, 0),
    "sequence_counter": (789, 0),
    "sequence_counter_link": (790, 0),
    "sequence_condition": (791, 0),
    "sequence_outputs": (792, 0),
    "sequence_trigger_position": (793, 0),
    "sequence_torque_or_ratio": (794, 0),
    # process data (PZD1), not PNUs
    "controlword": (CONTROL_WORD, 0),
    "statusword": (STATUS_WORD, 0),
    "position_set_point": (POSITION_SET_POINT, 0),  # PZD5-6: replaces PNU 767 every cycle
}

RESTORE_FIRST = (
    "max_motor_speed",
    "position_resolution",
    "encoder_increments",
    "encoder_input_selection",
    "encoder_input_resolution",
    "encoder_interpolation",
    "motor_feedback_selection",
    "sincos_feedback_tracks",
)
"""What a TTAPAR.TXT restore writes first: speeds are stored as % of 721, positions count in 740/870's units."""

FEEDBACK_PROGRAMMING = ProcedureAfterChange(
    "program_feedback",
    (
        "encoder_input_selection",
        "encoder_input_resolution",
        "encoder_interpolation",
        "motor_feedback_selection",
        "sincos_feedback_tracks",
    ),
    timeout=15.0,
)
"""PNU 894 after a restore changed 890-893/898: the selection is "only valid after the end of the Motor Feedback
Programmation procedure" (L3027-3110), which takes about 5 s on the drive (with the drive disabled)."""

SEQUENCE_FILE = "TTASEQ.TXT"
"""The backup of the 128 sequences (saved by PNU 781 per sequence, then 781 = 128), docs/profibus.md §13."""
SEQUENCE_BUFFER = SequenceBuffer(
    file=SEQUENCE_FILE,
    count=128,
    read="sequence_read",
    write="sequence_write",
    checksum_value=128,
    fields=(
        "sequence_control",
        "sequence_position",
        "sequence_speed",
        "sequence_acceleration",
        "sequence_deceleration",
        "sequence_time",
        "sequence_link",
        "sequence_counter",
        "sequence_counter_link",
        "sequence_condition",
        "sequence_outputs",
        "sequence_trigger_position",
        "sequence_torque_or_ratio",
    ),
)

#: the quick test's moves and homing: CW12 / CW13 toggled (to the PZD5-6 set point at PNU 760 rpm), CW11 rising
#: (PNU 766's configuration); ZSW12 toggles when the drive takes one, ZSW10 position reached, ZSW11 home found
MANUAL_MOTIONS = ManualMotions(
    absolute=ControlBit.ABSOLUTE_MOVE,
    relative=ControlBit.RELATIVE_MOVE,
    homing=ControlBit.HOMING,
    acknowledge=StatusBit.ACKNOWLEDGE,
    position_reached=StatusBit.POSITION_REACHED,
    home_found=StatusBit.HOME_FOUND,
    target="position_set_point",
)

TTAPRO = DeviceProfile(
    device="ttapro",
    objects=_OBJECTS,
    #: PNU 729 is a procedure: writing it saves every E parameter (the drive refuses it while enabled, error 17)
    procedure_values={"save": ("save_parameters", 1), "program_feedback": ("motor_feedback_programming", 1)},
    parameter_files={PARAMETER_FILE: SaveType.DRIVEPAR},
    #: the manual's restore order (L467-480 of the extraction, §5.2): 721 and 740/870 before what is scaled by them,
    #: the feedback selection 890-893/898 before the rest, then its programming (894) when the restore changed it;
    #: the save (729) at the end, with the drive disabled
    restore_first=RESTORE_FIRST,
    procedures_after_change=(FEEDBACK_PROGRAMMING,),
    sequence_buffer=SEQUENCE_BUFFER,
    save_needs_disabled=True,
    addressing=Addressing(node_ids=range(1, 126), reason="PROFIBUS-DP station addresses are 1-125"),
    #: what moves the axis or changes how it moves: the PZD control word (the guard judges it through the CiA 402
    #: transitions: its bits 0-3 and 7 are CiA 402's), the jog speed, and the writes that turn the motor or free the
    #: axis by themselves: the auto-phasing and auto-tuning procedures, the manual brake release (a vertical axis falls)
    motion_objects=frozenset(
        {
            "controlword",
            "position_set_point",
            "auto_phasing",
            "auto_tuning",
            "manual_brake",
            "jog_speed",
            "profile_velocity",
            "homing_configuration",
        }
    ),
    fieldbus=PROFIBUS_DP,
    controlword_fixed=ControlBit.PROFIBUS_CONTROL | ControlBit.NO_STOP | ControlBit.NO_INTERMEDIATE_STOP,
    #: the quick test's jog: CW8 / CW9 at the jog speed (PNU 763, rpm) while the bit stays set
    jog_bits=(ControlBit.JOG_PLUS, ControlBit.JOG_MINUS),
    manual_motions=MANUAL_MOTIONS,
    homing_methods=HOMING_CONFIGURATIONS,
    controlword_commands={QUICK_STOP: ControlBit.ON | ControlBit.NO_OFF2},
    #: faults polled (no EMCY): PNU 773 and 778 with the manual's texts, warnings PNU 873 (``ttapro_faults``)
    error_words=(("positioner_error_code", POSITIONER_ERRORS_FIRST), ("power_stage_fault_code", POWER_STAGE_FIRST)),
    coded_error_bits=(POWER_STAGE_CODE,),
    errors=ERRORS,
    warning_word="warning_code",
    warnings=WARNINGS,
)
