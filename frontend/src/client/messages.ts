/**
 * Payloads the OpenAPI schema does not describe, typed BY HAND here (and only here): the events of
 * `/api/ws/events`, the messages of `/api/ws/terminal`, and the results of server jobs (`JobModel.result` is `Any`
 * in the schema) and of a file restore (`PUT …/files/{name}` answers a plain dict).
 *
 * The backend builds these as dicts in several layers (drive/monitor.py, services/bus/connections.py and jobs.py,
 * services/backup.py, services/projects/live/commission.py, api/routes/events.py). Once they are pydantic models
 * (a discriminated union of events, typed job results, a response model for the file restore) they can be
 * generated into schema.d.ts like the REST payloads, and this file shrinks to aliases.
 */

import type { Schemas } from "./schema-types";

type ObjectValue = Schemas["ObjectValueModel"];
type JobModel = Schemas["JobModel"];

// ---- /api/ws/events -----------------------------------------------------------------------------------------------

/** What every event of a node carries (drive/monitor.py adds `bus` and `time`). */
interface NodeEvent {
  bus: string;
  node: number;
  time?: number;
}

export interface EventMap {
  /** First message: the motion client id every request then names (`X-Servo-Client`). */
  hello: { type: "hello"; client: string };
  bus_state: { type: "bus_state"; bus: string; connected: boolean; reason: string | null };
  bus_closed: { type: "bus_closed"; bus: string };
  scan: { type: "scan"; bus: string; nodes: Schemas["NodeIdentity"][] };
  emcy: NodeEvent & {
    type: "emcy";
    cia402_code: number;
    cia402_text: string;
    error_register: number;
    manufacturer: string;
    cleared: boolean;
    faults: Schemas["FaultInfoModel"][];
  };
  bootup: NodeEvent & { type: "bootup" };
  nmt_state: NodeEvent & { type: "nmt_state"; nmt_state: string };
  heartbeat_back: NodeEvent & { type: "heartbeat_back"; nmt_state: string };
  heartbeat_lost: NodeEvent & { type: "heartbeat_lost"; period_ms: number };
  drive_state: NodeEvent & { type: "drive_state"; state: string | null; statusword: number };
  /** Progress of a job: files and objects of one node, or a step of a project commission (`axes`). */
  progress: {
    type: "progress";
    job?: string;
    operation: string;
    node?: number;
    file?: string | null;
    done?: number;
    total?: number;
    project?: string;
    axis?: string;
    step?: string;
    axes?: { axis: string }[];
  };
  /** A job ended (or changed state): the job as `GET /api/jobs/{id}` answers it. */
  job: { type: "job" } & JobModel;
  overflow: { type: "overflow"; time: number; detail: string };
  /** The controller of an axis changed (docs/motion-safety.md): who holds it now, and what happened. */
  control: NodeEvent & {
    type: "control";
    event: "armed" | "released" | "taken_over" | "lost";
    holder: Schemas["HolderModel"] | null;
    requests: Schemas["HolderModel"][];
    by: { client: string | null; user?: string };
    previous?: Schemas["HolderModel"] | null;
  };
  /** Another client asks this page, the axis's controller, to release the axis. */
  control_request: NodeEvent & { type: "control_request"; to: string; from: { client: string; user: string } };
  /** A quick-test motion of an axis started, ended or changed (services/motion/jog.py): as `GET …/motion` gives it. */
  motion: { type: "motion" } & Schemas["MotionModel"];
  /** Not from the server: the event socket (re)opened. */
  ws_open: { type: "ws_open" };
}

export type EventType = keyof EventMap;

/** Any event as it arrives (the hub dispatches it by `type`; fields are checked where they are used). */
export type LiveEvent = { type: string } & Record<string, unknown>;

// ---- /api/ws/terminal ---------------------------------------------------------------------------------------------

export interface WatchItem {
  bus: string;
  node: number;
  object: string;
}

/** One monitored object in a `values` message. */
export interface WatchRow extends WatchItem {
  value?: ObjectValue;
  error?: string;
}

/** Server → client. */
export type TerminalMessage =
  | { type: "values"; rows: WatchRow[] }
  | { type: "written"; value: ObjectValue }
  | { type: "error"; detail: string };

// ---- job and file-restore results ---------------------------------------------------------------------------------

/** One file's restore result as the server reports it (`PUT …/files/{name}`; per node in a restore job). */
export interface RestoreAnswer {
  ok: boolean;
  cancelled: boolean;
  stored?: string | boolean;
  counts: Record<string, number>;
  error: string | null;
  objects: { label: string; status: string; error: string }[];
}

/** Result of a restore job: node → one answer per file. */
export type RestoreResult = Record<string, RestoreAnswer[]>;

export interface CommissionAxisResult {
  axis: string;
  node_id: number;
  bus_id: string | null;
  status: string;
  problem: string | null;
  ok: boolean;
  error: string | null;
  files: { file?: string; ok?: boolean; objects?: number; error?: string | null; counts?: Record<string, number> }[];
}

/** Result of a project commission job (`POST /api/projects/{p}/commission`). */
export interface CommissionResult {
  ok: boolean;
  direction: string;
  axes: CommissionAxisResult[];
}
