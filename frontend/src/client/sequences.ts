/**
 * Sequences (`api/routes/sequences.py`, docs/sequences.md): SEQUENCE.TXT checked with its chaining graph, the keyword
 * catalogue, the project's SEQUENCE.TXT of an axis, and the drive's sequence memory, programs and live monitor.
 * Start, stop and the inputs name this page's motion client (the `X-Servo-Client` header `api.request` adds): they
 * need the axis armed by this page.
 */

import { del, get, post, put } from "./api";
import { serverBus, whenMapped } from "./drives";
import type { Schemas } from "./schema-types";

export type SequenceCheck = Schemas["CheckModel"];
export type SequenceRow = Schemas["SequenceModel"];
export type SequenceGraph = Schemas["GraphModel"];
export type GraphEdge = Schemas["EdgeModel"];
export type SequenceIssue = Schemas["IssueModel"];
export type KeywordCatalog = Schemas["CatalogModel"];
export type Keyword = Schemas["KeywordModel"];
export type DriveSequences = Schemas["DriveSequencesModel"];
export type DownloadResult = Schemas["DownloadModel"];
export type MonitorSnapshot = Schemas["MonitorModel"];
export type ProjectSequences = Schemas["ProjectSequences"];
export type LoadMode = "load" | "merge";

const e = encodeURIComponent;
const nodePath = (bus: string, node: number) => `/api/buses/${e(serverBus(bus))}/nodes/${node}/sequences`;
const axisPath = (project: string, axis: string) => `/api/projects/${e(project)}/axes/${e(axis)}/sequences`;

export const sequencesApi = {
  keywords: () => get<KeywordCatalog>("/api/sequences/keywords"),
  check: (text: string) => post<SequenceCheck>("/api/sequences/check", { text }),
  project: (project: string, axis: string) => get<ProjectSequences>(axisPath(project, axis)),
  saveProject: (project: string, axis: string, text: string, revision: string | null) =>
    put<ProjectSequences>(axisPath(project, axis), { text, revision }),
  upload: (bus: string, node: number) => whenMapped(() => get<DriveSequences>(nodePath(bus, node))),
  download: (bus: string, node: number, text: string, mode: LoadMode, store: boolean) =>
    whenMapped(() => put<DownloadResult>(nodePath(bus, node), { text, mode, store })),
  store: (bus: string, node: number) => whenMapped(() => post<unknown>(`${nodePath(bus, node)}/store`)),
  start: (bus: string, node: number, sequence: number) =>
    whenMapped(() => post<unknown>(`${nodePath(bus, node)}/start`, { sequence })),
  stop: (bus: string, node: number) => whenMapped(() => post<unknown>(`${nodePath(bus, node)}/stop`)),
  inputs: (bus: string, node: number, conditional: string) =>
    whenMapped(() => put<Schemas["InputsModel"]>(`${nodePath(bus, node)}/inputs`, { conditional })),
  watch: (bus: string, node: number) =>
    whenMapped(() => post<MonitorSnapshot>(`${nodePath(bus, node)}/monitor?fresh=true`)),
  monitor: (bus: string, node: number) => whenMapped(() => get<MonitorSnapshot>(`${nodePath(bus, node)}/monitor`)),
  unwatch: (bus: string, node: number) => whenMapped(() => del<void>(`${nodePath(bus, node)}/monitor`)),
};
