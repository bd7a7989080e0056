/**
 * Compare: the project values of an axis against the defaults and the drive, or of several axes against each
 * other (same device), with the differing rows marked.
 *
 * Only what a user can write or restore is compared and counted: the entries the project holds (saved in a drive
 * file, writable). Read-only entries (error register, status word, measurements) change by themselves and no
 * restore sets them; they are offered apart ("read-only entries"), never counted as differences.
 */

import type { App, Page, PageContext } from "../app";
import { getDictionary, projects, type AxisConfig, type Project } from "../client/api";
import { driveApi } from "../client/drives";
import { errorText } from "../components/ui";
import { debounced, loader, type Loaded } from "../lib/async";
import { derive, h, Scope, state, type State } from "../lib/dom";
import { entries, entryKey, forNode, isReadable, isWritable, type Entry, type Scalar } from "../lib/od";
import { buildPath } from "../lib/router";
import { formatValue, sameValue } from "../lib/values";

const MAX_ROWS = 2000;
const FILTER_DELAY_MS = 150;

export interface Column {
  title: string;
  values: Map<string, Scalar>;
}

/** The values loaded for the chosen axes: one column per axis (and its drive), then the defaults. */
interface Comparison {
  list: Entry[];
  columns: Column[];
  /** The entries compared and counted (what the project holds); absent: every entry a column has. */
  counted?: Set<string>;
}

interface Options {
  axes: AxisConfig[];
  withDrive: boolean;
  withDefault: boolean;
  readOnly: boolean;
}

/** A read-only entry: shown apart, never counted. */
export function isReadOnly(entry: Entry): boolean {
  return isReadable(entry.variable.access) && !isWritable(entry.variable.access);
}

export async function comparePage(context: PageContext, name: string): Promise<Page> {
  const { app } = context;
  const project: Project = await projects.get(name);
  const scope = new Scope();
  const chosen = state<ReadonlySet<string>>(new Set(project.axes.slice(0, 2).map((axis) => axis.name)));
  const withDrive = state(false);
  const withDefault = state(true);
  const onlyDiff = state(true);
  const readOnly = state(false);
  const filterText = state("");
  const filter = debounced(scope, filterText, FILTER_DELAY_MS);
  const loaded = loader(scope, (): Options => ({
    axes: project.axes.filter((axis) => chosen.val.has(axis.name)), withDrive: withDrive.val, withDefault: withDefault.val,
    readOnly: readOnly.val,
  }), (options) => loadComparison(app, project, options));
  const shown = derive(() => shownRows(loaded.val, filter.val.trim().toLowerCase(), onlyDiff.val));
  const search = h("input", { type: "search", placeholder: "Filter by name or index", style: { width: "220px" },
    oninput: (event: Event) => (filterText.val = (event.target as HTMLInputElement).value) });
  return {
    title: `Compare ${project.name}`,
    crumbs: [h("a", { href: "/" }, "Projects"), " / ", h("a", { href: buildPath({ page: "project", project: project.name }) }, project.name), " / Compare"],
    focusSearch: () => { search.focus(); return true; },
    dispose: () => scope.dispose(),
    element: scope.run(() => h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Compare"),
        h("span", { class: "muted", "data-testid": "compare-summary" }, () => summary(shown.val))),
      h("div", { class: "toolbar" }, h("span", { class: "muted" }, "Axes:"), axisChoice(project, chosen),
        h("span", { class: "muted" }, "·"), checkbox(withDrive, "drive values", "compare-drive"),
        checkbox(withDefault, "defaults"), checkbox(onlyDiff, "only differences", "compare-only-diff"),
        checkbox(readOnly, "read-only entries (apart, not counted)", "compare-read-only"),
        search),
      h("div", { class: "panel", style: { overflow: "auto" } }, () => compareView(loaded.val, shown.val)),
      () => (readOnly.val && shown.val ? readOnlyView(shown.val) : null))),
  };
}

function checkbox(value: State<boolean>, label: string, testid?: string): HTMLElement {
  return h("label", { class: "check" }, h("input", {
    type: "checkbox", checked: value, "data-testid": testid, onchange: (event: Event) => (value.val = (event.target as HTMLInputElement).checked),
  }), label);
}

function axisChoice(project: Project, chosen: State<ReadonlySet<string>>): HTMLElement[] {
  return project.axes.map((axis) => h("label", { class: "check" }, h("input", {
    type: "checkbox", checked: () => chosen.val.has(axis.name), "data-testid": `compare-axis-${axis.name}`,
    onchange: (event: Event) => {
      const next = new Set(chosen.rawVal);
      if ((event.target as HTMLInputElement).checked) next.add(axis.name);
      else next.delete(axis.name);
      chosen.val = next;
    },
  }), axis.name));
}

async function loadComparison(app: App, project: Project, options: Options): Promise<Comparison | null> {
  const { axes } = options;
  if (axes.length === 0) return null;
  const devices = new Set(axes.map((axis) => axis.device));
  if (devices.size > 1) throw new Error(`The chosen axes use different devices (${[...devices].join(", ")}): compare axes of one device.`);
  // Defaults written as $NODEID+offset are resolved for the first chosen axis's node (its number in the title when
  // the chosen axes have several).
  const list = entries(forNode(await getDictionary(axes[0].device), axes[0].node_id));
  const defaultTitle = new Set(axes.map((axis) => axis.node_id)).size > 1 ? `default (node ${axes[0].node_id})` : "default";
  const readOnlyKeys = new Set(list.filter(isReadOnly).map((entry) => entry.key));
  const columns: Column[] = [];
  const counted = new Set<string>();
  for (const axis of axes) {
    const rows = (await projects.parameters(project.name, axis.name)).parameters;
    for (const row of rows) if (row.editable) counted.add(entryKey(row.index, row.subindex));
    columns.push({ title: `${axis.name} project`, values: new Map(rows.map((row) => [entryKey(row.index, row.subindex), row.value])) });
    if (options.withDrive && app.live.axis(axis.bus, axis.node_id)?.online) {
      const wanted = (key: string) => counted.has(key) || (options.readOnly && readOnlyKeys.has(key));
      const keys = rows.filter((row) => row.access !== "wo" && wanted(entryKey(row.index, row.subindex)))
        .map((row) => [row.index, row.subindex] as [number, number]);
      const values = await driveApi.readMany(axis.bus, axis.node_id, keys);
      columns.push({ title: `${axis.name} drive`, values: new Map(values.filter((v) => !v.error).map((v) => [entryKey(v.index, v.subindex), v.raw])) });
    }
  }
  if (options.withDefault) columns.push({ title: defaultTitle, values: new Map(list.map((entry) => [entry.key, entry.variable.default])) });
  return { list, columns, counted };
}

/** Whether the columns that have the entry disagree on its value. */
export function differs(columns: Column[], entry: Entry): boolean {
  const values = columns.filter((c) => c.values.has(entry.key)).map((c) => c.values.get(entry.key) ?? null);
  return values.some((value) => !sameValue(value, values[0]));
}

export interface ShownRows {
  columns: Column[];
  rows: Entry[];
  shown: Entry[];
  differing: number;
  /** The read-only entries of the filter (shown apart). */
  readOnly: Entry[];
}

/** The rows any column has, filtered by name or index, and of those the differing ones when asked. */
export function shownRows(loaded: Loaded<Comparison | null>, filter: string, onlyDifferences: boolean): ShownRows | null {
  if (loaded.status !== "ready" || !loaded.value) return null;
  const { list, columns, counted } = loaded.value;
  const matching = list.filter((entry) => columns.some((column) => column.values.has(entry.key)))
    .filter((entry) => !filter || entry.variable.name.toLowerCase().includes(filter) || entry.object.name.toLowerCase().includes(filter)
      || entry.object.index.toString(16).includes(filter.replace(/^0x/, "")));
  const rows = counted ? matching.filter((entry) => counted.has(entry.key)) : matching;
  const differing = rows.filter((entry) => differs(columns, entry));
  const readOnly = matching.filter(isReadOnly);
  return { columns, rows, shown: onlyDifferences ? differing : rows, differing: differing.length, readOnly };
}

function summary(shown: ShownRows | null): string {
  if (!shown) return "";
  const apart = shown.readOnly.length ? ` · ${shown.readOnly.length} read-only entries apart, not counted` : "";
  return `${shown.shown.length} rows shown · ${shown.differing} of ${shown.rows.length} writable entries differ${apart}`;
}

/** The read-only entries with their values (drive, defaults): to look at, not to write or restore. */
function readOnlyView(shown: ShownRows): HTMLElement {
  return h("section", { class: "panel", style: { overflow: "auto", marginTop: "12px" } },
    h("h2", null, `Read-only entries (${shown.readOnly.length}): the drive sets them; not written, restored or counted`),
    valueTable(shown.columns, shown.readOnly, "compare-read-only-table", () => ""));
}

function compareView(loaded: Loaded<Comparison | null>, shown: ShownRows | null): HTMLElement {
  if (loaded.status === "loading") return h("div", { class: "empty-state" }, "Loading values…");
  if (loaded.status === "failed") return h("div", { class: "message error" }, errorText(loaded.error));
  if (!shown) return h("div", { class: "empty-state" }, "Choose at least one axis.");
  const { columns } = shown;
  return valueTable(columns, shown.shown, "compare-table", (entry) => (differs(columns, entry) ? "differs" : ""));
}

function valueTable(columns: Column[], list: Entry[], testid: string, rowClass: (entry: Entry) => string): HTMLElement {
  return h("table", { class: "data", "data-testid": testid },
    h("thead", null, h("tr", null, h("th", null, "Index"), h("th", null, "Name"), h("th", null, "Unit"), columns.map((c) => h("th", { class: "num" }, c.title)))),
    h("tbody", null, list.slice(0, MAX_ROWS).map((entry) => h("tr", { class: rowClass(entry), "data-key": entry.key },
      h("td", { class: "mono" }, `0x${entry.object.index.toString(16).toUpperCase().padStart(4, "0")}.${entry.variable.subindex}`),
      h("td", { class: "wrap", style: { minWidth: "220px" } }, entry.variable.name === entry.object.name ? entry.variable.name : `${entry.object.name} › ${entry.variable.name}`),
      h("td", { class: "muted" }, entry.variable.unit),
      columns.map((c) => h("td", { class: "num mono" }, c.values.has(entry.key) ? formatValue(entry.variable, c.values.get(entry.key)) : ""))))));
}
