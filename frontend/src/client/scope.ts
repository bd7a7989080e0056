/**
 * The oscilloscope's server calls: the node's recorder (`/api/buses/{bus}/nodes/{node}/scope/…`: describe, check,
 * capture as a job, force, stop, the captures the server keeps) and the captures saved in a project under their
 * axis (`/api/projects/{project}/axes/{axis}/captures/…`).
 */

import { del, get, post } from "./api";
import { serverBus, whenMapped } from "./drives";
import type { JobInfo } from "./jobs";
import type { LiveEvent } from "./messages";
import type { Schemas } from "./schema-types";

export type ScopeInfo = Schemas["ScopeInfo"];
export type CaptureRequest = Schemas["CaptureRequest"];
export type CapturePlan = Schemas["PlanModel"];
export type CaptureData = Schemas["CaptureModel"];
export type CaptureChannel = Schemas["ChannelModel"];
export type RecorderStatus = Schemas["RecorderStatus"];
export type SavedCapture = Schemas["SavedCaptureModel"];
export type Preset = Schemas["PresetModel"];
export type ExportKind = "csv" | "html";
export type RollRequest = Schemas["RollRequest"];
export type RollStarted = Schemas["RollModel"];

/** What a capture job's result holds (`services/scope/service.py`). */
export interface CaptureJobResult {
  capture: string;
  captures: number;
}

/** A capture job's progress event: the recorder's stage, the upload's bytes, or a capture made. */
export interface ScopeProgress {
  job: string;
  stage: string;
  done?: number;
  total?: number;
  capture?: string;
}

const e = encodeURIComponent;
const nodePath = (bus: string, node: number) => `/api/buses/${e(serverBus(bus))}/nodes/${node}/scope`;
const axisPath = (project: string, axis: string) => `/api/projects/${e(project)}/axes/${e(axis)}/captures`;

export const scopeApi = {
  info: (bus: string, node: number) => whenMapped(() => get<ScopeInfo>(nodePath(bus, node))),
  check: (bus: string, node: number, request: CaptureRequest) =>
    whenMapped(() => post<CapturePlan>(`${nodePath(bus, node)}/check`, request)),
  start: (bus: string, node: number, request: CaptureRequest) =>
    whenMapped(() => post<JobInfo<CaptureJobResult>>(`${nodePath(bus, node)}/captures`, request)),
  status: (bus: string, node: number) => whenMapped(() => get<RecorderStatus>(`${nodePath(bus, node)}/status`)),
  force: (bus: string, node: number) => whenMapped(() => post<RecorderStatus>(`${nodePath(bus, node)}/force`)),
  stop: (bus: string, node: number) => whenMapped(() => post<RecorderStatus>(`${nodePath(bus, node)}/stop`)),
  capture: (bus: string, node: number, id: string) =>
    whenMapped(() => get<CaptureData>(`${nodePath(bus, node)}/captures/${e(id)}`)),
  exportUrl: (bus: string, node: number, id: string, kind: ExportKind) => `${nodePath(bus, node)}/captures/${e(id)}/${kind}`,
  /** Live roll mode: the server checks the bus budget (422 with the reason), then streams on `socket`. */
  roll: (bus: string, node: number, request: RollRequest) => whenMapped(() => post<RollStarted>(`${nodePath(bus, node)}/roll`, request)),
};

/** The roll's WebSocket (the answer's `socket` path) on this page's server. */
export function rollSocket(path: string): WebSocket {
  const protocol = window.location.protocol === "https:" ? "wss:" : "ws:";
  return new WebSocket(`${protocol}//${window.location.host}${path}`);
}

export const savedCaptures = {
  list: (project: string, axis: string) => get<SavedCapture[]>(axisPath(project, axis)),
  save: (project: string, axis: string, capture: string, name?: string) =>
    post<CaptureData>(axisPath(project, axis), { capture, name: name || null }),
  open: (project: string, axis: string, name: string) => get<CaptureData>(`${axisPath(project, axis)}/${e(name)}`),
  remove: (project: string, axis: string, name: string) => del<void>(`${axisPath(project, axis)}/${e(name)}`),
  exportUrl: (project: string, axis: string, name: string, kind: ExportKind) => `${axisPath(project, axis)}/${e(name)}/${kind}`,
};

/** A progress event of a capture job, or null for any other event. */
export function scopeProgress(event: LiveEvent): ScopeProgress | null {
  if (event.operation !== "scope" || typeof event.stage !== "string" || typeof event.job !== "string") return null;
  const number = (value: unknown) => (typeof value === "number" ? value : undefined);
  return {
    job: event.job,
    stage: event.stage,
    done: number(event.done),
    total: number(event.total),
    capture: typeof event.capture === "string" ? event.capture : undefined,
  };
}
