/**
 * The Bode page's server calls: frequency responses saved under an axis (`/api/projects/{p}/axes/{a}/frequency/…`:
 * list, open, CSV and HTML downloads, delete) and the drive's speed loop in physical units
 * (`/api/buses/{bus}/nodes/{node}/speed-loop`: read, write); a frequency-response measurement as a server job
 * (`POST /api/buses/{bus}/nodes/{node}/frequency-response`).
 */

import { del, get, post, put } from "./api";
import { serverBus, whenMapped } from "./drives";
import type { JobInfo } from "./jobs";
import type { LiveEvent } from "./messages";
import type { Schemas } from "./schema-types";

export type SavedSummary = Schemas["SavedFrequencySummary"];
export type SavedResult = Schemas["SavedFrequencyResult"];
export type SavedPoint = Schemas["SavedFrequencyPoint"];
export type SpeedLoop = Schemas["SpeedLoopModel"];
export type SpeedLoopChange = Schemas["SpeedLoopChange"];
export type SpeedLoopWrite = Schemas["SpeedLoopWrite"];
export type ExportKind = "csv" | "html";

const e = encodeURIComponent;
const axisPath = (project: string, axis: string) => `/api/projects/${e(project)}/axes/${e(axis)}/frequency`;

export const savedFrequency = {
  list: (project: string, axis: string) => get<SavedSummary[]>(axisPath(project, axis)),
  open: (project: string, axis: string, name: string) => get<SavedResult>(`${axisPath(project, axis)}/${e(name)}`),
  remove: (project: string, axis: string, name: string) => del<void>(`${axisPath(project, axis)}/${e(name)}`),
  /** A download link; the HTML overlays the results named in `compare`. */
  exportUrl: (project: string, axis: string, name: string, kind: ExportKind, compare: string[] = []) => {
    const query = kind === "html" && compare.length ? `?${compare.map((other) => `compare=${e(other)}`).join("&")}` : "";
    return `${axisPath(project, axis)}/${e(name)}/${kind}${query}`;
  },
};

const loopPath = (bus: string, node: number) => `/api/buses/${e(serverBus(bus))}/nodes/${node}/speed-loop`;

export const speedLoopApi = {
  get: (bus: string, node: number) => whenMapped(() => get<SpeedLoop>(loopPath(bus, node))),
  put: (bus: string, node: number, change: SpeedLoopChange) => whenMapped(() => put<SpeedLoopWrite>(loopPath(bus, node), change)),
};

/** What `POST …/frequency-response` takes (the safety settings, and the project axis to save the result under). */
export type MeasureBody = Schemas["FrequencyStart"];

/** The job's result: the result dict, with the name it was saved under. */
export type MeasureResult = Pick<SavedResult, "loop" | "points" | "markers" | "plant_fit" | "gains" | "aborted"> & { saved: string | null };

/** A measurement's progress event (stage, fraction 0..1), or null for any other event. */
export function measureProgress(event: LiveEvent): { stage: string; fraction: number } | null {
  if (event.operation !== "frequency-response" || typeof event.stage !== "string") return null;
  return { stage: event.stage, fraction: typeof event.fraction === "number" ? event.fraction : 0 };
}

export const measureApi = {
  start: (bus: string, node: number, body: MeasureBody) =>
    whenMapped(() => post<JobInfo<MeasureResult>>(`/api/buses/${e(serverBus(bus))}/nodes/${node}/frequency-response`, body)),
};
