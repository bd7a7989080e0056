/** The communication server's bus and drive routes (`/api/buses/…`): objects, state, faults, scan, NMT. */

import { get, post, put, request, projectAddress } from "./api";
import type { Scalar } from "../lib/od";

const e = encodeURIComponent;

export interface NodeIdentity {
  node: number;
  device: string | null;
  device_type: number | null;
  vendor_id: number | null;
  product_code: number | null;
  revision: number | null;
  serial_number: number | null;
  device_name: string | null;
  hardware_version: string | null;
  software_version: string | null;
}

export interface BusInfo {
  id: string;
  spec: string;
  kind: string;
  connected: boolean;
  error: string | null;
  nodes: NodeIdentity[];
}

export interface ObjectValue {
  node: number;
  index: number;
  sub: number;
  name: string;
  label: string;
  data_type: string;
  access: string;
  raw: number | string;
  physical: number | string;
  unit: string;
  text: string;
  bits: { name: string; first: number; last: number; value: number }[];
}

export interface ReadResult {
  object: string;
  value: ObjectValue | null;
  error: string | null;
}

export interface DriveStateInfo {
  node: number;
  state: string | null;
  statusword: number;
  nmt_state: string | null;
}

export interface FaultInfo {
  code: number;
  cia402_code: number;
  name: string;
  remedy: string;
}

export interface FaultReport {
  node: number;
  state: string | null;
  statusword: number;
  fault: boolean;
  error_code: number;
  error_text: string;
  faults: FaultInfo[];
  warnings: FaultInfo[];
}

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
 * opened that spec under another id ("bus0"). `setBuses` learns the mapping: same id first, else same spec.
 */
const aliases = new Map<string, string>();
let learned: () => void = () => undefined;
/** Resolves once the mapping was learned (after the app loaded projects and buses); drive calls wait for it. */
const aliasesKnown = new Promise<void>((resolve) => (learned = resolve));

export function learnBuses(server: BusInfo[], projectBuses: { name: string; interface: string }[]): void {
  learned();
  aliases.clear();
  for (const bus of projectBuses) {
    const match = server.find((candidate) => candidate.id === bus.name) ?? server.find((candidate) => candidate.spec === bus.interface);
    if (match) aliases.set(bus.name, match.id);
  }
}

/** Names under which the UI knows a server bus: its id and every project bus mapped to it. */
export function busNames(serverId: string): string[] {
  return [serverId, ...[...aliases].filter(([name, id]) => id === serverId && name !== serverId).map(([name]) => name)];
}

export function serverBus(bus: string): string {
  return aliases.get(bus) ?? bus;
}

const nodePath = (bus: string, node: number) => `/api/buses/${e(serverBus(bus))}/nodes/${node}`;

/** Drive calls wait until the bus mapping is known; the server identifies a node on first use (no scan needed). */
async function whenMapped<T>(work: () => Promise<T>): Promise<T> {
  await aliasesKnown;
  return work();
}

export const driveApi = {
  buses: () => get<BusInfo[]>("/api/buses"),
  bus: (bus: string) => get<BusInfo>(`/api/buses/${e(serverBus(bus))}`),
  openBus: (spec: string, id?: string) => post<BusInfo>("/api/buses", { spec, id: id || null }),
  closeBus: (bus: string) => aliasesKnown.then(() => request<void>("DELETE", `/api/buses/${e(serverBus(bus))}`)),
  scan: (bus: string) => aliasesKnown.then(() => post<NodeIdentity[]>(`/api/buses/${e(serverBus(bus))}/scan`)),
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
        values.push({ index, subindex, raw: result.value ? result.value.raw : null, error: result.error });
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
  fileUrl: (bus: string, node: number, name: string) => `${nodePath(bus, node)}/files/${e(name)}`,
};
