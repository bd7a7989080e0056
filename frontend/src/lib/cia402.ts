/**
 * CiA 402 device control: the state from the status word and the transitions a user may command from it
 * (manual L2861-3195). The UI offers exactly the transitions allowed in the current state.
 */

export type DriveState =
  | "not_ready_to_switch_on"
  | "switch_on_disabled"
  | "ready_to_switch_on"
  | "switched_on"
  | "operation_enabled"
  | "quick_stop_active"
  | "fault_reaction_active"
  | "fault";

export const STATE_LABELS: Record<DriveState, string> = {
  not_ready_to_switch_on: "Not ready to switch on",
  switch_on_disabled: "Switch on disabled",
  ready_to_switch_on: "Ready to switch on",
  switched_on: "Switched on",
  operation_enabled: "Operation enabled",
  quick_stop_active: "Quick stop active",
  fault_reaction_active: "Fault reaction active",
  fault: "Fault",
};

/** Decode bits 0,1,2,3,5,6 of the status word (table L3170-3185). */
export function decodeState(statusWord: number): DriveState {
  const masked6f = statusWord & 0x6f;
  const masked4f = statusWord & 0x4f;
  if (masked4f === 0x00) return "not_ready_to_switch_on";
  if (masked4f === 0x40) return "switch_on_disabled";
  if (masked6f === 0x21) return "ready_to_switch_on";
  if (masked6f === 0x23) return "switched_on";
  if (masked6f === 0x27) return "operation_enabled";
  if (masked6f === 0x07) return "quick_stop_active";
  if (masked4f === 0x0f) return "fault_reaction_active";
  if (masked4f === 0x08) return "fault";
  return "not_ready_to_switch_on";
}

export type Command =
  | "shutdown"
  | "switch_on"
  | "enable_operation"
  | "disable_operation"
  | "disable_voltage"
  | "quick_stop"
  | "fault_reset";

export const COMMAND_LABELS: Record<Command, string> = {
  shutdown: "Shutdown",
  switch_on: "Switch on",
  enable_operation: "Enable operation",
  disable_operation: "Disable operation",
  disable_voltage: "Disable voltage",
  quick_stop: "Quick stop",
  fault_reset: "Fault reset",
};

export interface Transition {
  number: number;
  command: Command;
  target: DriveState;
}

/** The transitions of table L2952-3042 a host can command (13, 14 are internal; 0, 1 happen at power-up). */
const TRANSITIONS: Record<DriveState, Transition[]> = {
  not_ready_to_switch_on: [],
  switch_on_disabled: [{ number: 2, command: "shutdown", target: "ready_to_switch_on" }],
  ready_to_switch_on: [
    { number: 3, command: "switch_on", target: "switched_on" },
    { number: 7, command: "disable_voltage", target: "switch_on_disabled" },
  ],
  switched_on: [
    { number: 4, command: "enable_operation", target: "operation_enabled" },
    { number: 6, command: "shutdown", target: "ready_to_switch_on" },
    { number: 10, command: "disable_voltage", target: "switch_on_disabled" },
  ],
  operation_enabled: [
    { number: 5, command: "disable_operation", target: "switched_on" },
    { number: 8, command: "shutdown", target: "ready_to_switch_on" },
    { number: 9, command: "disable_voltage", target: "switch_on_disabled" },
    { number: 11, command: "quick_stop", target: "quick_stop_active" },
  ],
  quick_stop_active: [
    { number: 12, command: "disable_voltage", target: "switch_on_disabled" },
    { number: 16, command: "enable_operation", target: "operation_enabled" },
  ],
  fault_reaction_active: [],
  fault: [{ number: 15, command: "fault_reset", target: "switch_on_disabled" }],
};

export function allowedTransitions(state: DriveState): Transition[] {
  return TRANSITIONS[state];
}

