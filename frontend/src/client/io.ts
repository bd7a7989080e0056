/**
 * I/O configuration (`api/routes/io.py`, docs/io.md): a drive's logic inputs with their functions and polarity, its
 * outputs, analog scaling, encoder emulation and CANopen I/O extension, the live I/O state, the fail-safe findings,
 * and on a simulated drive its test bench inputs (0x5F00).
 */

import { get, put } from "./api";
import { serverBus, whenMapped } from "./drives";
import type { Schemas } from "./schema-types";

export type IoConfig = Schemas["IoModel"];
export type IoLive = Schemas["IoLiveModel"];
export type IoInput = Schemas["IoInputModel"];
export type IoOutput = Schemas["IoOutputModel"];
export type IoGroup = Schemas["IoGroupModel"];
export type IoSetting = Schemas["IoSettingModel"];
export type IoFunction = Schemas["IoFunctionModel"];
export type IoFinding = Schemas["IoFindingModel"];
export type IoChange = Schemas["IoChangeRequest"];

const nodePath = (bus: string, node: number) => `/api/buses/${encodeURIComponent(serverBus(bus))}/nodes/${node}/io`;

export const ioApi = {
  read: (bus: string, node: number) => whenMapped(() => get<IoConfig>(nodePath(bus, node))),
  live: (bus: string, node: number) => whenMapped(() => get<IoLive>(`${nodePath(bus, node)}/state`)),
  change: (bus: string, node: number, change: IoChange) => whenMapped(() => put<IoConfig>(nodePath(bus, node), change)),
  simInputs: (bus: string, node: number, value: number) =>
    whenMapped(() => put<IoLive>(`${nodePath(bus, node)}/sim-inputs`, { value })),
};
