/** Typed access to the communication server's REST API (same origin). */

import type { Dictionary, DictionarySummary } from "../lib/od";
import type { Schemas } from "./schema-types";

export type Health = Schemas["Health"];
export type UserInfo = Schemas["UserModel"];

export type ErrorBody = Schemas["ErrorBody"];
export type ErrorKind = Schemas["ErrorKind"];

/**
 * A refusal of the server, with its message. The server answers `{detail, error, kind}` (`ErrorBody`): `detail` is
 * the message (or the list of problems of a malformed request), `error` the exception class, `kind` what the caller
 * can do about it. A body without them (a proxy's error page) leaves the path and the status.
 */
export class ApiError extends Error {
  constructor(
    readonly status: number,
    message: string,
    /** `not_found`, `invalid_input`, `conflict`, … ("" when the server did not say). */
    readonly kind: ErrorKind | "" = "",
    /** The server's exception class ("" when it did not say). */
    readonly error = "",
  ) {
    super(message);
  }
}

/** The problems of a malformed request as one line: `name: Field required; node_id: …`. */
function problemsText(problems: { loc?: unknown[]; msg?: string }[]): string {
  return problems.map((item) => `${(item.loc ?? []).slice(1).join(".")}: ${item.msg ?? ""}`).join("; ");
}

export async function errorOf(path: string, response: Response): Promise<ApiError> {
  let body: Partial<ErrorBody> | null = null;
  try {
    body = (await response.json()) as Partial<ErrorBody>;
  } catch {
    // Not JSON (a proxy error page, say): the status line is all there is.
  }
  const fallback = `${path}: HTTP ${response.status}`;
  const detail: unknown = body?.detail;
  const kind = body?.kind ?? "";
  const error = body?.error ?? "";
  if (typeof detail === "string") return new ApiError(response.status, detail, kind, error);
  if (Array.isArray(detail)) return new ApiError(response.status, problemsText(detail) || fallback, kind, error);
  return new ApiError(response.status, fallback, kind, error);
}

/** The cookie holding the session's CSRF token, and the header every state-changing request repeats it in. */
const CSRF_COOKIE = "servostudio_csrf";
const CSRF_HEADER = "X-CSRF-Token";
const SAFE_METHODS = new Set(["GET", "HEAD"]);

/** The session's CSRF token: only a page of the server's own origin can read the cookie, so a foreign page cannot
 * forge the header (docs/security.md). Null without a session (password-less use, no login yet). */
export function csrfToken(cookies: string = document.cookie): string | null {
  const entry = cookies.split("; ").find((cookie) => cookie.startsWith(`${CSRF_COOKIE}=`));
  return entry ? decodeURIComponent(entry.slice(CSRF_COOKIE.length + 1)) : null;
}

let whenUnauthenticated: () => void = () => undefined;

/** What to do when the server answers 401 (nobody logged in, the session ended): the app shows its login page. */
export function onUnauthenticated(handler: () => void): void {
  whenUnauthenticated = handler;
}

let motionClient: string | null = null;

/** The id the event socket announced. Every request names it, so the server can quick-stop the axes this page
 * enabled when the page goes away (enabling is refused without it). */
export function setMotionClient(id: string | null): void {
  motionClient = id;
}

export function getMotionClient(): string | null {
  return motionClient;
}

export async function request<T>(
  method: string,
  path: string,
  body?: unknown,
  fetchImpl: typeof fetch = fetch,
  signal?: AbortSignal,
): Promise<T> {
  const response = await exchange(method, path, body, fetchImpl, signal);
  if (response.status === 204) return undefined as T;
  return (await response.json()) as T;
}

/** One call, answered with the response itself (to read a header such as `X-Scan-Hint`) once it succeeded. */
export async function exchange(
  method: string,
  path: string,
  body?: unknown,
  fetchImpl: typeof fetch = fetch,
  signal?: AbortSignal,
): Promise<Response> {
  const init: RequestInit = { method, headers: { Accept: "application/json" }, signal };
  if (motionClient) (init.headers as Record<string, string>)["X-Servo-Client"] = motionClient;
  const csrf = SAFE_METHODS.has(method) ? null : csrfToken();
  if (csrf) (init.headers as Record<string, string>)[CSRF_HEADER] = csrf;
  if (body instanceof FormData || body instanceof Blob) {
    init.body = body;
    if (body instanceof Blob && body.type) (init.headers as Record<string, string>)["Content-Type"] = body.type;
  } else if (body !== undefined) {
    init.body = JSON.stringify(body);
    (init.headers as Record<string, string>)["Content-Type"] = "application/json";
  }
  const response = await fetchImpl(path, init);
  if (response.status === 401) whenUnauthenticated();
  if (!response.ok) throw await errorOf(path, response);
  return response;
}

export function getJson<T>(path: string, fetchImpl: typeof fetch = fetch): Promise<T> {
  return request<T>("GET", path, undefined, fetchImpl);
}

export const get = <T>(path: string, signal?: AbortSignal) => request<T>("GET", path, undefined, fetch, signal);
export const post = <T>(path: string, body?: unknown) => request<T>("POST", path, body ?? {});
export const put = <T>(path: string, body: unknown) => request<T>("PUT", path, body);
export const patch = <T>(path: string, body: unknown) => request<T>("PATCH", path, body);
export const del = <T>(path: string) => request<T>("DELETE", path);

/** Who the server says we are (name and user level). */
export function getMe(fetchImpl: typeof fetch = fetch): Promise<UserInfo> {
  return getJson<UserInfo>("/api/me", fetchImpl);
}

export function getHealth(fetchImpl: typeof fetch = fetch): Promise<Health> {
  return getJson<Health>("/api/health", fetchImpl);
}

const e = encodeURIComponent;

// ---- dictionaries -----------------------------------------------------------------------------------------------

const dictionaryCache = new Map<string, Promise<Dictionary>>();

/** Dictionaries do not change while the server runs (imports add new keys), so each is fetched once. */
export function getDictionary(device: string): Promise<Dictionary> {
  let cached = dictionaryCache.get(device);
  if (!cached) {
    cached = get<Dictionary>(`/api/dictionaries/${e(device)}`);
    cached.catch(() => dictionaryCache.delete(device));
    dictionaryCache.set(device, cached);
  }
  return cached;
}

export const listDictionaries = () => get<DictionarySummary[]>("/api/dictionaries");

export function importDictionary(eds: File, props: File | null): Promise<DictionarySummary> {
  const form = new FormData();
  form.append("eds", eds);
  if (props) form.append("props", props);
  return post<DictionarySummary>("/api/dictionaries", form);
}

// ---- projects ---------------------------------------------------------------------------------------------------

// The payloads are the server's pydantic models (generated into schema.d.ts by `make api-types`).
export type BusConfig = Schemas["BusModel"];
export type AxisConfig = Schemas["AxisModel"];
export type Project = Schemas["ProjectModel"];
export type ProjectSummary = Schemas["ProjectSummary"];
export type ProjectParameter = Schemas["ParameterModel"];
export type ParameterList = Schemas["ParameterList"];
export type CompareRow = Schemas["CompareRowModel"];
export type Comparison = Schemas["CompareModel"];
export type Motor = Schemas["MotorModel"];
export type AxisChoice = Schemas["AxisChoiceModel"];
export type Template = Schemas["TemplateModel"];
export type KeptRevision = Schemas["KeptRevisionModel"];
export type DcfImport = Schemas["DcfImportModel"];
type ProjectChange = Schemas["ProjectUpdate"];
type AxisChange = Schemas["AxisUpdate"];

/** The address form of the projects API: `0x60F9,2`. */
export function projectAddress(index: number, subindex: number): string {
  return `0x${index.toString(16).toUpperCase().padStart(4, "0")},${subindex}`;
}

const axisPath = (project: string, axis: string) => `/api/projects/${e(project)}/axes/${e(axis)}`;

export const projects = {
  list: () => get<ProjectSummary[]>("/api/projects"),
  get: (name: string) => get<Project>(`/api/projects/${e(name)}`),
  create: (name: string, description: string, buses: BusConfig[]) =>
    post<Project>("/api/projects", { name, description, buses }),
  update: (name: string, change: ProjectChange) =>
    patch<Project>(`/api/projects/${e(name)}`, change),
  remove: (name: string, revision: string) => del<void>(`/api/projects/${e(name)}?revision=${e(revision)}`),
  rename: (name: string, newName: string, revision: string) =>
    post<Project>(`/api/projects/${e(name)}/rename`, { new_name: newName, revision }),
  duplicate: (name: string, newName: string) => post<Project>(`/api/projects/${e(name)}/duplicate`, { new_name: newName }),
  archiveUrl: (name: string) => `/api/projects/${e(name)}/archive`,
  unarchive: (archive: Blob, newName?: string) =>
    post<Project>(`/api/projects/unarchive${newName ? `?new_name=${e(newName)}` : ""}`,
      new Blob([archive], { type: "application/zip" })),
  addAxis: (project: string, axis: Omit<AxisConfig, "motor" | "application">, revision: string) =>
    post<Project>(`/api/projects/${e(project)}/axes`, { ...axis, revision }),
  editAxis: (project: string, axis: string, change: AxisChange) =>
    patch<Project>(axisPath(project, axis), change),
  removeAxis: (project: string, axis: string, revision: string) =>
    del<Project>(`${axisPath(project, axis)}?revision=${e(revision)}`),
  parameters: (project: string, axis: string) =>
    get<ParameterList>(`${axisPath(project, axis)}/parameters?include_unsaved=true`),
  setParameters: (project: string, axis: string, values: Record<string, number | string>, revision?: string, keepRevision = false) =>
    put<ParameterList>(`${axisPath(project, axis)}/parameters`, { values, revision, keep_revision: keepRevision }),
  /** The project as it was before each change that replaced many values, newest first. */
  revisions: (name: string) => get<KeptRevision[]>(`/api/projects/${e(name)}/revisions`),
  restoreRevision: (name: string, kept: string, revision?: string) =>
    post<Project>(`/api/projects/${e(name)}/revisions/${e(kept)}/restore`, { revision }),
  resetParameters: (project: string, axis: string, addresses: string[], revision?: string) =>
    post<ParameterList>(`${axisPath(project, axis)}/parameters/reset`, { addresses, revision }),
  compare: (project: string, axis: string, onlyDifferences: boolean) =>
    get<Comparison>(
      `${axisPath(project, axis)}/compare?only_differences=${onlyDifferences}`,
    ),
  selectMotor: (project: string, axis: string, reference: string, revision: string) =>
    post<AxisChoice>(`${axisPath(project, axis)}/motor`, { reference, revision }),
  application: (project: string, axis: string) => get<Template | null>(`${axisPath(project, axis)}/application`),
  applyApplication: (project: string, axis: string, template: string, revision: string) =>
    post<AxisChoice>(`${axisPath(project, axis)}/application`, { template, revision }),
  dcfUrl: (project: string, axis: string) => `${axisPath(project, axis)}/dcf`,
  /** Set the axis's offline values to what a DCF configures (all or nothing); `changes` says what changes (old,
   * new), `skipped` what it left out. With `dryRun` the server checks it all and writes nothing. */
  importDcf: (project: string, axis: string, dcf: File, revision: string, dryRun = false) => {
    const form = new FormData();
    form.append("dcf", dcf);
    return post<DcfImport>(`${axisPath(project, axis)}/dcf?revision=${e(revision)}&dry_run=${dryRun}`, form);
  },
  templates: (device: string) => get<Template[]>(`/api/device-templates?device=${e(device)}`),
  motors: () => get<Motor[]>("/api/motors"),
};

/**
 * Store many values in a project; values the project refuses (a drive may hold a value outside the dictionary's
 * range) are left out one by one and reported, so one odd value does not block a backup of hundreds.
 */
export async function setParametersSkipping(
  project: string,
  axis: string,
  values: Record<string, number | string>,
  keepRevision = false,
): Promise<{ parameters: ProjectParameter[]; skipped: string[] }> {
  const remaining = { ...values };
  const skipped: string[] = [];
  for (;;) {
    try {
      const answer = await projects.setParameters(project, axis, remaining, undefined, keepRevision);
      return { parameters: answer.parameters, skipped };
    } catch (error) {
      const address = error instanceof ApiError && error.status === 422 ? /0x[0-9A-F]{4},\d+/i.exec(error.message)?.[0] : undefined;
      const key = address && Object.keys(remaining).find((candidate) => candidate.toUpperCase() === address.toUpperCase());
      if (!key) throw error;
      skipped.push(error instanceof Error ? error.message : String(error));
      delete remaining[key];
      if (Object.keys(remaining).length === 0) return { parameters: [], skipped };
    }
  }
}
