/**
 * Tool-side identification (`POST /api/buses/{bus}/nodes/{node}/identification`, docs/identification.md): the
 * experiment runs as a server job (operation `identification`, its `progress` events on the socket, cancel = quick
 * stop); the result's `identified` has auto-tuning's keys. The options are typed by the generated schema; the job's
 * result is not in it (`JobModel.result` is open) and is typed here after the pinned CLI JSON.
 */

import { post } from "./api";
import { serverBus, whenMapped } from "./drives";
import type { JobInfo } from "./jobs";
import type { Identified } from "./procedures";
import type { Schemas } from "./schema-types";

export type IdentificationOptions = Schemas["IdentificationOptions"];

/** The tuning after the identification (gain objects, or the encoTRive's inertia setting): gains before → after in
 * physical units and the verification's speed step with its measured bandwidth. */
export interface TuningAfterIdentification {
  bandwidth_hz: number;
  gains: { before: Record<string, unknown>; after: Record<string, unknown> };
  verification: { speed_step: { bandwidth_hz: number | null; overshoot_pct: number | null } | null; skipped?: string } | null;
}

export interface IdentificationResult {
  kind: "identification";
  status: string;
  node: number;
  device: string;
  time: string;
  identified: Identified & { residual: number | null };
  experiment: Record<string, number | string>;
  tuning?: TuningAfterIdentification;
}

export interface IdentificationClient {
  start(bus: string, node: number, options: IdentificationOptions, bandwidth: number | null): Promise<JobInfo<IdentificationResult>>;
}

const e = encodeURIComponent;

export const identificationApi: IdentificationClient = {
  start: (bus, node, options, bandwidth) => whenMapped(() =>
    post<JobInfo<IdentificationResult>>(`/api/buses/${e(serverBus(bus))}/nodes/${node}/identification`, { options, bandwidth_hz: bandwidth })),
};
