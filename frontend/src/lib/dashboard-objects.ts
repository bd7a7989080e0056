/**
 * Which dictionary entries the axis dashboard shows, by the semantic names of the device's profile: the server's
 * dictionary answer maps each name the device has to its address (`names`: `statusword` is 0x6041 on a CANopen
 * drive, the PZD status word on a TTA-PRO), so no table of raw addresses lives here. Temperatures are manufacturer
 * objects, found by their unit. Only entries the device has are shown.
 */

import { entries, type Dictionary, type Entry } from "./od";

/**
 * The measurements in the order the dashboard lists them; a row of names is one readout, the first name the device
 * has (the TTA-PRO's DC bus voltage PNU where CiA 402 has 0x6079). The TTA-PRO's speed and current monitors are
 * shares of the maximum speed and of the drive rating (their own names: not CiA 402 velocity and current).
 */
export const MEASUREMENTS: string[][] = [
  ["position_actual"],
  ["velocity_actual"],
  ["speed_monitor"],
  ["current_actual"],
  ["current_monitor"],
  ["torque_actual"],
  ["following_error_actual"],
  ["dc_link_voltage", "dc_bus_voltage"],
];

/** The CiA 402 value of profile velocity mode in `modes_of_operation`. */
export const PROFILE_VELOCITY_MODE = 3;

export interface DashboardSignals {
  statusword: Entry | null;
  mode: Entry | null;
  modeDisplay: Entry | null;
  measurements: Entry[];
  inputs: Entry | null;
  outputs: Entry | null;
  /** Profile velocity quick test (manual §1.8.19): target velocity, acceleration, deceleration. */
  targetVelocity: Entry | null;
  acceleration: Entry | null;
  deceleration: Entry | null;
  /** The device has CANopen's NMT (a PROFIBUS-DP drive has none). */
  nmt: boolean;
}

/** The entry of the first of `names` that the device has, else null. */
export function namedEntry(dictionary: Dictionary, all: Entry[], ...names: string[]): Entry | null {
  for (const name of names) {
    const address = dictionary.names[name];
    const found = address && all.find((entry) => entry.object.index === address[0] && entry.variable.subindex === address[1]);
    if (found) return found;
  }
  return null;
}

export function dashboardSignals(dictionary: Dictionary): DashboardSignals {
  const all = entries(dictionary);
  const find = (...names: string[]) => namedEntry(dictionary, all, ...names);
  const standard = MEASUREMENTS.map((names) => find(...names)).filter((entry): entry is Entry => entry !== null);
  const temperatures = all.filter((entry) => entry.variable.unit === "°C" && entry.variable.access.toLowerCase() === "ro");
  return {
    statusword: find("statusword"),
    mode: find("modes_of_operation"),
    modeDisplay: find("modes_of_operation_display"),
    measurements: [...standard, ...temperatures.filter((entry) => !standard.includes(entry))],
    inputs: find("digital_inputs"),
    outputs: find("digital_outputs"),
    targetVelocity: find("target_velocity"),
    acceleration: find("profile_acceleration"),
    deceleration: find("profile_deceleration"),
    nmt: dictionary.fieldbus === "CANopen",
  };
}
