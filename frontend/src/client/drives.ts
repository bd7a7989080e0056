/** The communication server's bus and drive routes (`/api/buses/…`): objects, state, faults, scan, NMT. */

import { exchange, get, post, put, request, projectAddress } from "./api";
import type { Scalar } from "../lib/od";
import { state, type State } from "../lib/dom";
import type { Schemas } from "./schema-types";

const e = encodeURIComponent;

// The payloads are the server's pydantic models (generated into schema.d.ts by `make api-types`).
export type NodeIdentity = Schemas["NodeIdentity"];
/** A scan's answer; `hint` (the `X-Scan-Hint` header) says why a bus may look empty, null when nodes were found. */
export interface ScanResult {
  nodes: NodeIdentity[];
  hint: string | null;
}
export type BusInfo = Schemas["BusStatus"];
export type ObjectValue = Schemas["ObjectValueModel"];
export type ReadResult = Schemas["ReadResult"];
export type DriveStateInfo = Schemas["DriveState"];
export type FaultInfo = Schemas["FaultInfoModel"];
export type FaultReport = Schemas["FaultReportModel"];
export type StoreAnswer = Schemas["StoreModel"];

/** One value of a batch read, keyed like the dictionary. */
export interface ReadValue {
  index: number;
  subindex: number;
  raw: Scalar;
  error: string | null;
}

const MAX_BATCH = 256;

/**
 * Project bus name → the server's bus id. A project names its bus ("sim") and gives its spec; the server may have
 * opened that spec under another id ("bus0"). `learnBuses` learns the mapping from the server (`POST /api/buses/match`:
 * same spec however spelt, else same name). The
 * mapping is a state, so a binding that shows `serverBus(…)` follows it.
 */
const aliases: State<ReadonlyMap<string, string>> = state(new Map());
let learned: () => void = () => undefined;
/** Resolves once the mapping was learned (after the app loaded projects and buses); drive calls wait for it. */
const aliasesKnown = new Promise<void>((resolve) => (learned = resolve));

export type BusMatch = Schemas["BusMatchModel"];
/** The server's answer per project bus name: which open bus it is and by what (spec, name); the project page shows it. */
export const busMatches: State<ReadonlyMap<string, BusMatch>> = state(new Map());
let matchRequests = 0;
/** The question whose answer the mapping holds. */
let appliedRequest = 0;

export function learnBuses(server: BusInfo[], projectBuses: { name: string; interface: string }[]): void {
  const open = new Set(server.map((candidate) => candidate.id));
  const next = new Map<string, string>();
  for (const bus of projectBuses) {
    // While the server is asked again, its last answer stands for a bus that is still open: a guess from the spelling
    // of the spec would send the calls made meanwhile to a bus that does not exist.
    const decided = aliases.rawVal.get(bus.name);
    const match = server.find((candidate) => candidate.id === bus.name) ?? server.find((candidate) => candidate.spec === bus.interface);
    const id = decided !== undefined && open.has(decided) ? decided : match?.id;
    if (id) next.set(bus.name, id);
  }
  aliases.val = next;
  const asked = ++matchRequests;
  if (server.length === 0 || projectBuses.length === 0) return learned();
  // The server compares specs as it parses them (`socketcand:h:p` is `socketcand:h:p/can0`): its answer decides.
  // Answers are applied in the order of the questions (one that comes after a later question's answer is dropped),
  // and drive calls wait until an answer is applied: never released by an answer that was dropped.
  void post<BusMatch[]>("/api/buses/match", { buses: projectBuses.map((bus) => ({ name: bus.name, spec: bus.interface })) })
    .then((matches) => {
      if (asked < appliedRequest) return;
      appliedRequest = asked;
      aliases.val = new Map(matches.flatMap((match) => (match.bus ? [[match.name, match.bus] as [string, string]] : [])));
      busMatches.val = new Map(matches.map((match) => [match.name, match]));
    }, () => undefined)
    .finally(learned);
}

/** Names under which the UI knows a server bus: its id and every project bus mapped to it. */
export function busNames(serverId: string): string[] {
  return [serverId, ...[...aliases.rawVal].filter(([name, id]) => id === serverId && name !== serverId).map(([name]) => name)];
}

export function serverBus(bus: string): string {
  return aliases.val.get(bus) ?? bus;
}

const nodePath = (bus: string, node: number) => `/api/buses/${e(serverBus(bus))}/nodes/${node}`;

/** Drive calls wait until the bus mapping is known; the server identifies a node on first use (no scan needed). */
export async function whenMapped<T>(work: () => Promise<T>): Promise<T> {
  await aliasesKnown;
  return work();
}

export const driveApi = {
  buses: () => get<BusInfo[]>("/api/buses"),
  bus: (bus: string) => get<BusInfo>(`/api/buses/${e(serverBus(bus))}`),
  openBus: (spec: string, id?: string) => post<BusInfo>("/api/buses", { spec, id: id || null }),
  closeBus: (bus: string) => aliasesKnown.then(() => request<void>("DELETE", `/api/buses/${e(serverBus(bus))}`)),
  /** The nodes found, and when there are none the server's reasons why the bus may look empty for its kind. */
  scan: (bus: string) => aliasesKnown.then(async (): Promise<ScanResult> => {
    const response = await exchange("POST", `/api/buses/${e(serverBus(bus))}/scan`, {});
    return { nodes: (await response.json()) as NodeIdentity[], hint: response.headers.get("X-Scan-Hint") };
  }),
  nmt: (bus: string, command: string, node = 0) =>
    aliasesKnown.then(() => post<void>(`/api/buses/${e(serverBus(bus))}/nmt`, { command, node })),

  read: (bus: string, node: number, key: string) => whenMapped(() => get<ObjectValue>(`${nodePath(bus, node)}/objects/${e(key)}`)),
  writeKey: (bus: string, node: number, key: string, value: number | string, physical = false) =>
    whenMapped(() => put<ObjectValue>(`${nodePath(bus, node)}/objects/${e(key)}`, { value, physical })),
  readKeys: (bus: string, node: number, keys: string[], signal?: AbortSignal) =>
    whenMapped(() => request<ReadResult[]>("POST", `${nodePath(bus, node)}/read`, { objects: keys }, fetch, signal)),

  /** Read many (index, sub) in batches of the server's limit; a failing object carries its error. */
  async readMany(bus: string, node: number, keys: [number, number][], signal?: AbortSignal): Promise<ReadValue[]> {
    const values: ReadValue[] = [];
    for (let start = 0; start < keys.length; start += MAX_BATCH) {
      const chunk = keys.slice(start, start + MAX_BATCH);
      const results = await driveApi.readKeys(bus, node, chunk.map(([index, sub]) => projectAddress(index, sub)), signal);
      results.forEach((result, position) => {
        const [index, subindex] = chunk[position];
        values.push({ index, subindex, raw: result.value ? result.value.raw : null, error: result.error ?? null });
      });
    }
    return values;
  },

  /** Write a raw value; answers the value read back by the server. */
  async write(bus: string, node: number, index: number, subindex: number, raw: number | string): Promise<Scalar> {
    const value = await driveApi.writeKey(bus, node, projectAddress(index, subindex), raw);
    return value.raw;
  },

  state: (bus: string, node: number) => whenMapped(() => get<DriveStateInfo>(`${nodePath(bus, node)}/state`)),
  setState: (bus: string, node: number, target: string) =>
    whenMapped(() => put<DriveStateInfo>(`${nodePath(bus, node)}/state`, { target })),
  faults: (bus: string, node: number) => whenMapped(() => get<FaultReport>(`${nodePath(bus, node)}/faults`)),
  resetFaults: (bus: string, node: number) => whenMapped(() => post<FaultReport>(`${nodePath(bus, node)}/faults/reset`)),
  /** Store the drive's parameters in its non-volatile memory (the device's own save, the dictionary's `store`). */
  store: (bus: string, node: number) => whenMapped(() => post<StoreAnswer>(`${nodePath(bus, node)}/store`)),
  fileUrl: (bus: string, node: number, name: string) => `${nodePath(bus, node)}/files/${e(name)}`,
};
