/**
 * One controller per axis (`/api/buses/{bus}/nodes/{node}/control…`) and the audit log (`/api/audit`). Every call
 * names this page's motion client (the `X-Servo-Client` header `api.request` adds), so arming makes this page the
 * axis's controller; the rules are in docs/motion-safety.md.
 */

import { get, getMotionClient, post } from "./api";
import { serverBus, whenMapped } from "./drives";
import type { Schemas } from "./schema-types";

export type AxisControl = Schemas["AxisControlModel"];
export type Holder = Schemas["HolderModel"];
export type AuditPage = Schemas["AuditPageModel"];

/** One audit entry (the columns of docs/security.md, Audit log); only `seq`, `time` and `action` are always there. */
export interface AuditEntry {
  seq: number;
  time: string;
  action: string;
  user?: string | null;
  client?: string | null;
  axis?: string | null;
  project?: string | null;
  project_axis?: string | null;
  object?: string | null;
  name?: string | null;
  old?: unknown;
  new?: unknown;
  result?: string | null;
  detail?: string | null;
}

/** The filters of the audit view; empty values are left out of the query. */
export interface AuditFilters {
  axis?: string;
  user?: string;
  action?: string;
  since?: string;
  until?: string;
}

const e = encodeURIComponent;
const controlPath = (bus: string, node: number) => `/api/buses/${e(serverBus(bus))}/nodes/${node}/control`;

export const controlApi = {
  get: (bus: string, node: number) => whenMapped(() => get<AxisControl>(controlPath(bus, node))),
  arm: (bus: string, node: number) => whenMapped(() => post<AxisControl>(`${controlPath(bus, node)}/arm`)),
  release: (bus: string, node: number) => whenMapped(() => post<AxisControl>(`${controlPath(bus, node)}/release`)),
  request: (bus: string, node: number) => whenMapped(() => post<AxisControl>(`${controlPath(bus, node)}/request`)),
  takeOver: (bus: string, node: number) => whenMapped(() => post<AxisControl>(`${controlPath(bus, node)}/take-over`)),
};

/** Whether this page is the axis's controller. */
export function heldByMe(control: AxisControl | null): boolean {
  return control?.holder != null && control.holder.client === getMotionClient();
}

/** Who holds the axis, as the dashboard says it. */
export function holderText(control: AxisControl | null): string {
  if (!control) return "…";
  if (!control.holder) return "Not armed: nobody answers for this axis";
  if (heldByMe(control)) return "Armed by this page";
  return `Armed by ${control.holder.user} (client ${control.holder.client})`;
}

export function auditQuery(filters: AuditFilters, extra: Record<string, string> = {}): string {
  const params = new URLSearchParams();
  for (const [key, value] of Object.entries({ ...filters, ...extra })) if (value) params.set(key, value);
  return params.toString();
}

export const auditApi = {
  page: (filters: AuditFilters, offset: number, limit: number) =>
    get<AuditPage>(`/api/audit?${auditQuery(filters, { offset: String(offset), limit: String(limit) })}`),
  exportUrl: (filters: AuditFilters, format: "csv" | "jsonl") => `/api/audit/export?${auditQuery(filters, { format })}`,
};
