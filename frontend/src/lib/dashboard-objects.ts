/**
 * Which dictionary entries the axis dashboard shows. CiA 402 fixes the indices of the standard signals for every
 * drive; temperatures are manufacturer objects, found by their unit. Only entries the dictionary has are shown.
 */

import { entries, type Dictionary, type Entry } from "./od";

/** CiA 402 (IEC 61800-7-201) measurement objects, in the order the dashboard lists them. */
export const STANDARD_MEASUREMENTS: [number, number][] = [
  [0x6064, 0], // position actual value
  [0x606c, 0], // velocity actual value
  [0x6078, 0], // current actual value
  [0x6077, 0], // torque actual value
  [0x60f4, 0], // following error actual value
  [0x6079, 0], // DC link circuit voltage
];

export const STATUSWORD: [number, number] = [0x6041, 0];
export const MODE: [number, number] = [0x6060, 0];
export const MODE_DISPLAY: [number, number] = [0x6061, 0];
export const DIGITAL_INPUTS: [number, number] = [0x60fd, 0];
export const DIGITAL_OUTPUTS: [number, number] = [0x60fe, 1];
/** Profile velocity quick test (manual §1.8.19): target velocity, acceleration, deceleration. */
export const TARGET_VELOCITY: [number, number] = [0x60ff, 0];
export const PROFILE_ACCELERATION: [number, number] = [0x6083, 0];
export const PROFILE_DECELERATION: [number, number] = [0x6084, 0];
/** The CiA 402 value of profile velocity mode in 0x6060. */
export const PROFILE_VELOCITY_MODE = 3;

export interface DashboardSignals {
  statusword: Entry | null;
  mode: Entry | null;
  modeDisplay: Entry | null;
  measurements: Entry[];
  inputs: Entry | null;
  outputs: Entry | null;
  targetVelocity: Entry | null;
  acceleration: Entry | null;
  deceleration: Entry | null;
}

export function dashboardSignals(dictionary: Dictionary): DashboardSignals {
  const all = entries(dictionary);
  const find = ([index, sub]: [number, number]) =>
    all.find((entry) => entry.object.index === index && entry.variable.subindex === sub) ?? null;
  const standard = STANDARD_MEASUREMENTS.map(find).filter((entry): entry is Entry => entry !== null);
  const temperatures = all.filter((entry) => entry.variable.unit === "°C" && entry.variable.access.toLowerCase() === "ro");
  return {
    statusword: find(STATUSWORD),
    mode: find(MODE),
    modeDisplay: find(MODE_DISPLAY),
    measurements: [...standard, ...temperatures],
    inputs: find(DIGITAL_INPUTS),
    outputs: find(DIGITAL_OUTPUTS),
    targetVelocity: find(TARGET_VELOCITY),
    acceleration: find(PROFILE_ACCELERATION),
    deceleration: find(PROFILE_DECELERATION),
  };
}
