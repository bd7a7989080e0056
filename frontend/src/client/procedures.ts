/**
 * The drive's guided procedures (`/api/buses/{bus}/nodes/{node}/procedures…`, contract of issue #13): the list with
 * each procedure's preconditions read from the drive now, a start as a server job (operation
 * `procedure:<name>`; its progress arrives as `progress` events, an abort is the job's cancel), the undo of an
 * auto-tuning, and the results saved in a project under their axis.
 *
 * The list and the undo are typed by the generated schema; the job results are not in it (`JobModel.result` is
 * open): they are typed here, after the pinned CLI JSON of the issue, like the scope's capture result in
 * `client/scope.ts`.
 */

import { get, post } from "./api";
import { serverBus, whenMapped } from "./drives";
import type { JobInfo } from "./jobs";
import type { LiveEvent } from "./messages";
import type { Schemas } from "./schema-types";

export type ProcedureName = "auto_phasing" | "motor_phasing" | "current_loop" | "current_limits" | "auto_tuning";
export type ProcedureStatus = Schemas["ProcedureModel"]["status"];

export type Precondition = Schemas["PreconditionModel"];

/** One procedure of the drive, as `GET …/procedures` lists it: `moves` — it turns the motor and needs the axis
 * armed by this page; `ready` — every precondition is met (each unmet one has the manual's reason). */
export type ProcedureInfo = Schemas["ProcedureModel"];

export interface TuningOptions {
  bandwidth: 50 | 75 | 100;
  filter: "standard" | "anti-resonance" | "max-stiffness";
  speed_filter: "auto" | "0.5" | "1" | "2";
  mode: "min-following-error" | "min-overshoot";
}

export interface CurrentLoopOptions {
  /** Phase-to-phase, written to the motor data first when given. */
  inductance_mh: number | null;
  regulator: "high" | "low" | null;
}

export interface StartRequest {
  options: Partial<TuningOptions> | Partial<CurrentLoopOptions> | Record<string, never>;
  verify: boolean;
  project: string | null;
  axis: string | null;
}

/** Semantic name → raw value, before and after the procedure. */
export interface Change {
  before: Record<string, number>;
  after: Record<string, number>;
}

export interface Commutation {
  pole_pairs: number;
  phase_order: number;
  sensor_offset: number;
}

/** A recorded step: reference and response over time, with what was measured on it. */
export interface StepMeasure {
  rise_time_s: number | null;
  overshoot_pct: number | null;
  settling_time_s: number | null;
  bandwidth_hz: number | null;
  /** The speed steps' own bandwidths (null: that step did not settle); `bandwidth_hz` is their mean response's. */
  bandwidth_steps_hz?: (number | null)[];
  capture: { time_s: number[]; reference: number[]; response: number[]; unit: string };
}

/** The plant per N·m/A of torque constant, in amperes: what a drive without a torque constant (CD1-k) identifies. */
export interface PerAmpere {
  inertia_as2_per_rad: number | null;
  viscous_friction_as_per_rad: number | null;
  coulomb_friction_a: number | null;
  load_torque_a: number | null;
}

/** The physical values are null when the drive identifies per ampere only (`per_ampere`). */
export interface Identified {
  inertia_kgm2: number | null;
  viscous_friction_nms_per_rad: number | null;
  coulomb_friction_nm: number | null;
  load_torque_nm: number | null;
  /** Total inertia over the motor's own (null when the motor's is not known). */
  inertia_ratio: number | null;
  per_ampere?: PerAmpere;
}

/** What every procedure result carries; the rest depends on the procedure (pinned CLI JSON + these keys). */
export interface ResultBase {
  status: string;
  procedure?: string;
  /** The project file the result was saved to, or null. */
  saved?: string | null;
  /** In the list of saved results: the file's name, and why it could not be read. */
  file?: string;
  error?: string;
}

/** Auto-phasing's verification move: torque per ampere against the expected value (≥ 98 % passes). */
export interface PhasingCheck {
  torque_per_ampere_ratio: number | null;
  passed: boolean | null;
  /** The commutation angle's error, electrical degrees. */
  error_deg?: number | null;
  /** Why the check could not measure, or was not made. */
  reason?: string;
  skipped?: string;
}

/** Auto-tuning's verification: a speed step, and a position step when tuned in a position mode. */
export interface TuningCheck {
  speed_step: StepMeasure | null;
  position_step: StepMeasure | null;
}

/** Any procedure's result: the keys its procedure gives are there (auto-phasing: the commutation and `before`). */
export interface ProcedureResult extends ResultBase, Partial<Commutation> {
  before?: Partial<Commutation>;
  identified?: Identified;
  gains?: Change;
  limits?: Change;
  verification?: PhasingCheck | TuningCheck;
}

export function isPhasingCheck(check: ProcedureResult["verification"]): check is PhasingCheck {
  return check !== undefined && "torque_per_ampere_ratio" in check;
}

export function isTuningCheck(check: ProcedureResult["verification"]): check is TuningCheck {
  return check !== undefined && "speed_step" in check;
}

/** A `progress` event of a procedure job. */
export interface ProcedureProgress {
  job: string;
  procedure: string;
  phase: "preconditions" | "running" | "reading" | "verifying" | "done" | string;
  status: ProcedureStatus | string;
  elapsed_s: number;
  fraction: number | null;
  message: string;
}

const e = encodeURIComponent;
const nodePath = (bus: string, node: number) => `/api/buses/${e(serverBus(bus))}/nodes/${node}/procedures`;

/** The undo's answer: the gains as read back after the write. */
export type UndoResult = Schemas["UndoResult"];

/** The calls the procedure pages make; the components take it as a parameter, so tests pass a fake one. */
export interface ProceduresClient {
  list(bus: string, node: number): Promise<ProcedureInfo[]>;
  start(bus: string, node: number, name: string, request: StartRequest): Promise<JobInfo<ProcedureResult>>;
  undo(bus: string, node: number, gains: Record<string, number>): Promise<UndoResult>;
  saved(project: string, axis: string): Promise<ProcedureResult[]>;
}

export const proceduresApi: ProceduresClient = {
  list: (bus, node) => whenMapped(() => get<ProcedureInfo[]>(nodePath(bus, node))),
  start: (bus, node, name, request) =>
    whenMapped(() => post<JobInfo<ProcedureResult>>(`${nodePath(bus, node)}/${e(name)}`, request)),
  undo: (bus, node, gains) => whenMapped(() => post<UndoResult>(`${nodePath(bus, node)}/auto_tuning/undo`, { gains })),
  saved: (project, axis) => get<ProcedureResult[]>(`/api/projects/${e(project)}/axes/${e(axis)}/procedures`),
};

/** A progress event of a procedure job, or null for any other event. */
export function procedureProgress(event: LiveEvent): ProcedureProgress | null {
  if (typeof event.job !== "string" || typeof event.procedure !== "string" || typeof event.phase !== "string") return null;
  return {
    job: event.job,
    procedure: event.procedure,
    phase: event.phase,
    status: typeof event.status === "string" ? event.status : "unknown",
    elapsed_s: typeof event.elapsed_s === "number" ? event.elapsed_s : 0,
    fraction: typeof event.fraction === "number" ? event.fraction : null,
    message: typeof event.message === "string" ? event.message : "",
  };
}

/** The UTC time in a saved result's file name (`<name>-<YYYYMMDDTHHMMSS.ffffffZ>.json`) as `YYYY-MM-DD HH:MM:SS`, or "". */
export function savedTime(result: ResultBase): string {
  const match = /-(\d{4})(\d\d)(\d\d)T(\d\d)(\d\d)(\d\d)(\.\d+)?Z\.json$/.exec(result.file ?? result.saved ?? "");
  return match ? `${match[1]}-${match[2]}-${match[3]} ${match[4]}:${match[5]}:${match[6]}` : "";
}
