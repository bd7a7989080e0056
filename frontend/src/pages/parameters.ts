/**
 * Parameter editor: every object of a dictionary in the manual's groups, searchable, with the drive value, the
 * project value and the default side by side. Used for an axis (drive + project) and for a bare dictionary.
 */

import type { ProjectParameter } from "../client/api";
import { confirmAction, errorText, toast } from "../components/ui";
import { VirtualList } from "../components/vlist";
import { decodeBits, fieldLabel, insertBits } from "../lib/bits";
import { h, replaceChildren } from "../lib/dom";
import { formatHex } from "../lib/numbers";
import {
  address,
  entries as allEntries,
  enumOptions,
  hexWidth,
  isReadable,
  isVar,
  isWritable,
  shortType,
  valueKind,
  type Dictionary,
  type Entry,
  type OdObject,
  type Scalar,
} from "../lib/od";
import { decodePointer, encodePointer, formatPointer } from "../lib/pointer";
import type { Location } from "../lib/router";
import { buildIndex, search, type Searchable } from "../lib/search";
import { editText, formatRange, formatValue, parseValue, sameValue, unstorableReason } from "../lib/values";

export interface DriveCell {
  raw: Scalar;
  error?: string;
}

/** Where values come from and go to; either side may be absent (bare dictionary, offline axis). */
export interface ParameterSources {
  drive: null | {
    online(): boolean;
    read(entries: Entry[], signal: AbortSignal): Promise<Map<string, DriveCell>>;
    write(entry: Entry, raw: number | string): Promise<Scalar>;
  };
  project: null | {
    load(): Promise<ProjectParameter[]>;
    write(changes: { entry: Entry; raw: number | string }[]): Promise<ProjectParameter[]>;
    reset(entries: Entry[]): Promise<ProjectParameter[]>;
  };
  /** Query (search, group) changed: keep it in the URL. */
  onQuery(query: Record<string, string | undefined>): void;
  /** The axis's application template (Device Config): the editor opens on only the groups it needs. */
  application?: { title: string; groups: string[] } | null;
}

type Row =
  | { kind: "group"; name: string; count: number }
  | { kind: "object"; object: OdObject }
  | { kind: "entry"; entry: Entry; sub: boolean };

const ROW_HEIGHT = 24;
const READ_CHUNK = 40;
const ALL_GROUPS = "";
const APPLICATION_GROUPS = "@application";
/** `?group=*`: every group, although the axis has an application template (Expert mode). */
const EXPERT_QUERY = "*";
const TARGETS_KEY = "servostudio.writeTargets";

export class ParameterEditor {
  readonly element: HTMLElement;
  private readonly list: VirtualList<Row>;
  private readonly index: Searchable[];
  private readonly entryList: Entry[];
  private readonly byKey = new Map<string, Entry>();
  private readonly drive = new Map<string, DriveCell>();
  private readonly project = new Map<string, ProjectParameter>();
  private readonly pendingReads = new Set<string>();
  private readonly searchInput: HTMLInputElement;
  private readonly groupSelect: HTMLSelectElement;
  private readonly onlyDiff: HTMLInputElement;
  private readonly countLabel: HTMLElement;
  private readonly bulk: HTMLElement;
  private readonly detail: HTMLElement;
  private shown: Entry[] = [];
  private selected: Entry | null = null;
  private readTimer = 0;
  private abort = new AbortController();
  private bulkRunning: AbortController | null = null;
  private editor: HTMLElement | null = null;
  private editorKey = "";
  private readingForDiff = false;
  private readonly applicationGroups: Set<string>;

  constructor(
    private readonly dictionary: Dictionary,
    private readonly sources: ParameterSources,
    location: Location,
  ) {
    this.entryList = allEntries(dictionary);
    for (const entry of this.entryList) this.byKey.set(entry.key, entry);
    this.index = buildIndex(this.entryList);
    this.searchInput = h("input", {
      type: "search", placeholder: "Search index, name or description ( / )", style: { width: "300px" },
      "data-testid": "param-search", "aria-label": "Search parameters",
    });
    const application = sources.application ?? null;
    this.applicationGroups = new Set(application?.groups ?? []);
    this.groupSelect = h("select", { "data-testid": "param-group", "aria-label": "Group" },
      application ? h("option", { value: APPLICATION_GROUPS }, `${application.title}: its groups`) : null,
      h("option", { value: ALL_GROUPS }, application ? "All groups (Expert)" : "All groups"),
      dictionary.groups.map((group) => h("option", { value: group }, group)));
    this.onlyDiff = h("input", { type: "checkbox", "data-testid": "param-only-diff" });
    this.countLabel = h("span", { class: "muted", "data-testid": "param-count" });
    this.bulk = h("span", { class: "toolbar" });
    this.list = new VirtualList<Row>(ROW_HEIGHT, (row) => this.renderRow(row));
    this.list.onVisible = (rows) => this.scheduleRead(rows);
    this.detail = h("div", { class: "panel detail", "data-testid": "param-detail" });

    this.searchInput.value = location.query.q ?? "";
    this.groupSelect.value = this.initialGroup(location.query.group, application !== null);
    let typingTimer = 0;
    this.searchInput.addEventListener("input", () => {
      clearTimeout(typingTimer);
      typingTimer = window.setTimeout(() => this.applyFilter(true), 60);
    });
    this.searchInput.addEventListener("keydown", (event) => {
      if (event.key === "ArrowDown" || event.key === "Enter") {
        event.preventDefault();
        this.moveSelection(0, true);
        this.list.element.focus();
      }
    });
    this.groupSelect.addEventListener("change", () => this.applyFilter(true));
    this.onlyDiff.addEventListener("change", () => void this.onlyDifferences());
    this.list.element.addEventListener("keydown", (event) => this.onTableKey(event));
    this.list.element.addEventListener("click", (event) => {
      const row = (event.target as Element).closest<HTMLElement>(".prow.entry");
      if (row?.dataset.key) this.select(this.byKey.get(row.dataset.key)!, false);
    });
    this.list.element.addEventListener("dblclick", () => this.focusEditor());

    const header = h("div", { class: "prow head" },
      h("span", null, "Index"), h("span", null, "Name"),
      h("span", { class: "num" }, sources.drive ? "Drive" : "Value"), h("span", null, "Unit"),
      h("span", { class: "num" }, sources.project ? "Project" : ""), h("span", { class: "num" }, "Default"),
      h("span", null, "Type"));
    const toolbar = h("div", { class: "toolbar" },
      this.searchInput, this.groupSelect,
      sources.drive && sources.project ? h("label", { class: "check", title: "Only entries whose drive value differs from the project" }, this.onlyDiff, "Only differences") : null,
      this.countLabel, h("span", { class: "grow" }), this.bulk);
    this.element = h("div", { class: "page fill" }, toolbar,
      h("div", { class: "params" },
        h("div", { class: "panel ptable", "data-testid": "param-table" }, header, this.list.element),
        this.detail));
    this.renderBulk();
    this.renderDetail();
  }

  /** Load project values, then show rows (drive values are read as rows come into view). */
  async start(): Promise<void> {
    this.applyFilter(false);
    if (this.sources.project) await this.loadProject();
  }

  dispose(): void {
    this.abort.abort();
    this.bulkRunning?.abort();
    clearTimeout(this.readTimer);
  }

  /** The drive went on- or offline: read the rows in view, update buttons and the detail pane. */
  onlineChanged(): void {
    if (this.onlyDiff.checked && this.sources.drive?.online() && !this.bulkRunning) void this.onlyDifferences();
    this.list.refresh();
    this.renderBulk();
    this.renderDetail();
  }

  focusSearch(): boolean {
    this.searchInput.focus();
    this.searchInput.select();
    return true;
  }

  /** Query-only URL change (back/forward between searches): update the filter in place. */
  update(location: Location): boolean {
    const q = location.query.q ?? "";
    const group = this.initialGroup(location.query.group, this.applicationGroups.size > 0);
    if (q !== this.searchInput.value || group !== this.groupSelect.value) {
      this.searchInput.value = q;
      this.groupSelect.value = group;
      this.applyFilter(false);
    }
    return true;
  }

  // ---- filtering and rows -------------------------------------------------------------------------------------

  /** The group from the URL when it names one; else the application's groups when a template is chosen. */
  private initialGroup(fromUrl: string | undefined, hasApplication: boolean): string {
    if (fromUrl === EXPERT_QUERY) return ALL_GROUPS;
    if (fromUrl !== undefined && this.dictionary.groups.includes(fromUrl)) return fromUrl;
    return hasApplication ? APPLICATION_GROUPS : ALL_GROUPS;
  }

  /** The URL form of a group choice: the default (the application's groups, or all without one) is left out. */
  private groupQuery(group: string): string | undefined {
    if (group === APPLICATION_GROUPS) return undefined;
    if (group === ALL_GROUPS) return this.applicationGroups.size > 0 ? EXPERT_QUERY : undefined;
    return group;
  }

  private applyFilter(updateUrl: boolean): void {
    const text = this.searchInput.value;
    const group = this.groupSelect.value;
    let found = search(this.index, text);
    if (group === APPLICATION_GROUPS) found = found.filter((entry) => this.applicationGroups.has(entryGroup(entry)));
    else if (group !== ALL_GROUPS) found = found.filter((entry) => entryGroup(entry) === group);
    if (this.onlyDiff.checked && !this.readingForDiff) found = found.filter((entry) => this.differs(entry));
    this.shown = found;
    const rows = text.trim() ? found.map((entry): Row => ({ kind: "entry", entry, sub: false })) : this.groupRows(found);
    this.list.setItems(rows);
    this.list.element.scrollTop = 0;
    this.countLabel.textContent = `${found.length} of ${this.entryList.length} entries`;
    if (updateUrl) this.sources.onQuery({ q: text.trim() || undefined, group: this.groupQuery(group) });
    if (found.length > 0 && (!this.selected || !found.includes(this.selected))) this.select(found[0], false);
    this.renderBulk();
  }

  /** Rows grouped as in the manual: group header, then objects in index order, ARRAY/RECORD with their subs. */
  private groupRows(found: Entry[]): Row[] {
    const byGroup = new Map<string, Entry[]>();
    for (const entry of found) {
      const group = entryGroup(entry);
      if (!byGroup.has(group)) byGroup.set(group, []);
      byGroup.get(group)!.push(entry);
    }
    const order = [...this.dictionary.groups, ...[...byGroup.keys()].filter((g) => !this.dictionary.groups.includes(g))];
    const rows: Row[] = [];
    for (const group of order) {
      const list = byGroup.get(group);
      if (!list) continue;
      rows.push({ kind: "group", name: group, count: list.length });
      let lastObject: OdObject | null = null;
      for (const entry of list) {
        const compound = !isVar(entry.object);
        if (compound && entry.object !== lastObject) rows.push({ kind: "object", object: entry.object });
        lastObject = entry.object;
        rows.push({ kind: "entry", entry, sub: compound });
      }
    }
    return rows;
  }

  private renderRow(row: Row): HTMLElement {
    if (row.kind === "group") {
      return h("div", { class: "prow group" }, h("span", null, row.name), h("span", { class: "count" }, `${row.count}`));
    }
    if (row.kind === "object") {
      return h("div", { class: "prow object" }, h("span", { class: "mono" }, formatHex(row.object.index)),
        h("span", null, row.object.name), h("span", { class: "muted" }, row.object.kind));
    }
    const { entry } = row;
    const variable = entry.variable;
    const driveCell = this.drive.get(entry.key);
    const projectRow = this.project.get(entry.key);
    const differs = this.differs(entry);
    const writable = isWritable(variable.access);
    let driveText: Node | string = "";
    if (driveCell?.error) driveText = h("span", { class: "cell-error", title: driveCell.error }, "read error");
    else if (driveCell) driveText = h("span", { class: differs ? "differs" : "", title: differs ? `differs from the project value ${formatValue(variable, projectRow?.value)}` : "" }, formatValue(variable, driveCell.raw));
    else if (!this.sources.drive) driveText = h("span", { class: "stale" }, formatValue(variable, variable.default));
    const name: (Node | string)[] = row.sub || isVar(entry.object) || variable.name === entry.object.name
      ? [variable.name]
      : [variable.name, h("span", { class: "muted" }, ` · ${entry.object.name}`)];
    return h("div", {
      class: `prow entry ${row.sub ? "sub" : ""} ${this.selected === entry ? "selected" : ""}`,
      "data-key": entry.key, "data-address": address(entry), title: variable.description || variable.name,
    },
      h("span", { class: "mono" }, address(entry)),
      h("span", { class: `name ${writable ? "" : "ro"}` }, ...name),
      h("span", { class: "num mono", "data-col": "drive" }, driveText),
      h("span", { class: "muted" }, variable.unit),
      h("span", { class: `num mono ${projectRow?.file ? "" : "stale"}`, "data-col": "project" }, projectRow ? formatValue(variable, projectRow.value) : ""),
      h("span", { class: "num mono stale" }, formatValue(variable, variable.default)),
      h("span", { class: "muted", title: `${variable.data_type}, ${variable.access}` }, `${shortType(variable.data_type)}${writable ? "" : " " + variable.access}`),
    );
  }

  private differs(entry: Entry): boolean {
    const driveCell = this.drive.get(entry.key);
    const projectRow = this.project.get(entry.key);
    if (!driveCell || driveCell.error || !projectRow || projectRow.value === null) return false;
    return !sameValue(driveCell.raw, projectRow.value);
  }

  // ---- selection and keyboard ---------------------------------------------------------------------------------

  private onTableKey(event: KeyboardEvent): void {
    if (event.key === "ArrowDown" || event.key === "ArrowUp") {
      event.preventDefault();
      this.moveSelection(event.key === "ArrowDown" ? 1 : -1, false);
    } else if (event.key === "Enter") {
      event.preventDefault();
      this.focusEditor();
    }
  }

  private moveSelection(step: number, fromStart: boolean): void {
    if (this.shown.length === 0) return;
    const position = fromStart || !this.selected ? -1 : this.shown.indexOf(this.selected);
    const next = this.shown[Math.min(this.shown.length - 1, Math.max(0, position + (fromStart ? 1 : step)))];
    this.select(next, true);
  }

  private select(entry: Entry, scroll: boolean): void {
    this.selected = entry;
    if (scroll) {
      for (let position = 0; position < this.list.count(); position++) {
        const row = this.list.itemAt(position);
        if (row?.kind === "entry" && row.entry === entry) {
          this.list.scrollToPosition(position);
          break;
        }
      }
    }
    this.list.refresh();
    this.renderDetail();
    if (this.sources.drive?.online() && isReadable(entry.variable.access) && !this.drive.has(entry.key)) {
      void this.readEntries([entry], this.abort.signal);
    }
  }

  private focusEditor(): void {
    const editor = this.detail.querySelector<HTMLInputElement | HTMLSelectElement>("[data-editor]");
    editor?.focus();
    if (editor instanceof HTMLInputElement) editor.select();
  }

  // ---- drive values -------------------------------------------------------------------------------------------

  /** Read the drive values of rows that came into view and have none yet, batched and debounced. */
  private scheduleRead(rows: Row[]): void {
    if (!this.sources.drive?.online()) return;
    for (const row of rows) {
      if (row.kind === "entry" && !this.drive.has(row.entry.key) && isReadable(row.entry.variable.access)) {
        this.pendingReads.add(row.entry.key);
      }
    }
    clearTimeout(this.readTimer);
    this.readTimer = window.setTimeout(() => {
      const keys = [...this.pendingReads];
      this.pendingReads.clear();
      const wanted = keys.map((key) => this.byKey.get(key)!).filter((entry) => !this.drive.has(entry.key));
      if (wanted.length) void this.readEntries(wanted, this.abort.signal);
    }, 120);
  }

  private async readEntries(list: Entry[], signal: AbortSignal, progress?: (done: number) => void): Promise<void> {
    const drive = this.sources.drive;
    if (!drive) return;
    const readable = list.filter((entry) => isReadable(entry.variable.access));
    for (let start = 0; start < readable.length; start += READ_CHUNK) {
      if (signal.aborted) return;
      const chunk = readable.slice(start, start + READ_CHUNK);
      try {
        const values = await drive.read(chunk, signal);
        for (const [key, cell] of values) this.drive.set(key, cell);
      } catch (error) {
        if (signal.aborted) return;
        for (const entry of chunk) this.drive.set(entry.key, { raw: null, error: errorText(error) });
      }
      progress?.(Math.min(readable.length, start + READ_CHUNK));
      this.list.refresh();
      if (this.selected && chunk.includes(this.selected)) this.renderDetail();
    }
    this.renderBulk();
  }

  // ---- project values -----------------------------------------------------------------------------------------

  private async loadProject(): Promise<void> {
    try {
      const rows = await this.sources.project!.load();
      this.setProjectRows(rows);
    } catch (error) {
      toast(`Project values: ${errorText(error)}`, "error");
    }
  }

  private setProjectRows(rows: ProjectParameter[]): void {
    for (const row of rows) this.project.set(`${row.index}.${row.subindex}`, row);
    this.list.refresh();
    this.renderDetail();
    this.renderBulk();
  }

  // ---- writing ------------------------------------------------------------------------------------------------

  private targets(): { drive: boolean; project: boolean } {
    const stored = localStorage.getItem(TARGETS_KEY);
    const parsed = stored ? (JSON.parse(stored) as { drive: boolean; project: boolean }) : { drive: true, project: true };
    const driveOk = Boolean(this.sources.drive?.online());
    const projectOk = Boolean(this.sources.project);
    const result = { drive: driveOk && parsed.drive, project: projectOk && parsed.project };
    if (!result.drive && !result.project) return { drive: driveOk, project: !driveOk && projectOk };
    return result;
  }

  private setTargets(targets: { drive: boolean; project: boolean }): void {
    localStorage.setItem(TARGETS_KEY, JSON.stringify(targets));
  }

  /** Write one value to the chosen targets; the server validates and its message is shown on refusal. */
  private async writeValue(entry: Entry, raw: number | string, status: HTMLElement): Promise<void> {
    const targets = this.targets();
    const done: string[] = [];
    status.className = "muted";
    status.textContent = "Writing…";
    try {
      if (targets.drive && this.sources.drive) {
        const readBack = await this.sources.drive.write(entry, raw);
        this.drive.set(entry.key, { raw: readBack });
        done.push("drive");
      }
      if (targets.project && this.sources.project && entry.variable.save_type !== "NONE") {
        this.setProjectRows(await this.sources.project.write([{ entry, raw }]));
        done.push("project");
      }
    } catch (error) {
      this.list.refresh();
      if (this.editor) this.editor.dataset.keep = "1";
      status.className = "error-text";
      status.textContent = errorText(error);
      status.dataset.testid = "param-error";
      return;
    }
    this.list.refresh();
    this.editor = null;
    this.renderDetail();
    const message = done.length ? `${address(entry)} = ${formatValue(entry.variable, raw)} written to ${done.join(" and ")}` : "Nothing to write to";
    const newStatus = this.detail.querySelector<HTMLElement>("[data-status]");
    if (newStatus) {
      newStatus.className = done.length ? "ok-text" : "error-text";
      newStatus.textContent = message;
    }
  }

  // ---- bulk operations ----------------------------------------------------------------------------------------

  private renderBulk(): void {
    if (this.bulkRunning) return;
    const items: Node[] = [];
    const drive = this.sources.drive;
    const project = this.sources.project;
    if (drive) {
      items.push(h("button", {
        disabled: !drive.online() || this.shown.length === 0, title: "Read the shown entries from the drive again",
        "data-testid": "param-refresh", onclick: () => this.bulkRefresh(),
      }, "Refresh"));
    }
    if (drive && project) {
      // Differences are known for the entries read so far; "+" says unread entries may add some (read on click).
      const more = drive.online() && this.unread(this.shown).length > 0 ? "+" : "";
      const toDrive = this.toDrive();
      const toProject = this.toProject();
      items.push(
        h("button", {
          disabled: !drive.online() || (toDrive.length === 0 && !more), "data-testid": "param-write-changed",
          title: "Write the project values that differ from the drive into the drive (unread entries are read first)",
          onclick: () => this.bulkWriteDrive(),
        }, `Write changed → drive (${toDrive.length}${more})`),
        h("button", {
          disabled: toProject.length === 0 && !more, "data-testid": "param-revert",
          title: "Take the drive values of the differing entries into the project (unread entries are read first)",
          onclick: () => this.bulkToProject(),
        }, `Drive → project (${toProject.length}${more})`),
      );
    }
    if (project) {
      const explicit = this.shown.filter((entry) => this.project.get(entry.key)?.file);
      items.push(h("button", {
        disabled: explicit.length === 0, "data-testid": "param-reset",
        title: "Remove the shown values from the project files: they fall back to the defaults",
        onclick: () => this.bulkReset(explicit),
      }, `Reset to defaults (${explicit.length})`));
    }
    replaceChildren(this.bulk, ...items);
  }

  /** Run a long operation with a progress bar and a cancel button in place of the bulk buttons. */
  private async runBulk(label: string, total: number, work: (signal: AbortSignal, progress: (done: number) => void) => Promise<void>): Promise<boolean> {
    const controller = new AbortController();
    this.bulkRunning = controller;
    const bar = h("progress", { max: String(Math.max(1, total)), value: "0", style: { width: "160px" } });
    const text = h("span", { class: "muted" }, `${label} 0/${total}`);
    replaceChildren(this.bulk, text, bar, h("button", { "data-testid": "bulk-cancel", onclick: () => controller.abort() }, "Cancel"));
    const progress = (done: number) => {
      bar.value = done;
      text.textContent = `${label} ${done}/${total}`;
    };
    try {
      await work(controller.signal, progress);
      if (controller.signal.aborted) toast(`${label}: cancelled`);
      return !controller.signal.aborted;
    } catch (error) {
      toast(`${label}: ${errorText(error)}`, "error");
      return false;
    } finally {
      this.bulkRunning = null;
      this.list.refresh();
      this.renderBulk();
      this.renderDetail();
    }
  }

  private unread(list: Entry[]): Entry[] {
    return list.filter((entry) => isReadable(entry.variable.access) && !this.drive.has(entry.key));
  }

  private toDrive(): Entry[] {
    return this.shown.filter((entry) => this.project.get(entry.key)?.file && this.differs(entry) && isWritable(entry.variable.access));
  }

  private toProject(): Entry[] {
    return this.shown.filter((entry) => this.differs(entry) && this.project.get(entry.key)?.editable);
  }

  /** Read the drive values a comparison needs but has not yet (rows never scrolled into view). */
  private async readMissing(signal: AbortSignal, progress: (done: number) => void): Promise<void> {
    const missing = this.unread(this.shown);
    if (missing.length && this.sources.drive?.online()) await this.readEntries(missing, signal, progress);
  }

  /** "Only differences" compares every shown entry: read the missing drive values first, then filter. */
  private async onlyDifferences(): Promise<void> {
    if (this.onlyDiff.checked && this.sources.drive?.online()) {
      this.readingForDiff = true;
      this.applyFilter(false);
      const missing = this.unread(this.shown);
      const complete = missing.length === 0
        || (await this.runBulk("Reading", missing.length, (signal, progress) => this.readEntries(missing, signal, progress)));
      this.readingForDiff = false;
      if (!complete) this.onlyDiff.checked = false;
    }
    this.applyFilter(false);
  }

  private bulkRefresh(): void {
    const list = this.shown.filter((entry) => isReadable(entry.variable.access));
    for (const entry of list) this.drive.delete(entry.key);
    void this.runBulk("Reading", list.length, (signal, progress) => this.readEntries(list, signal, progress));
  }

  private async bulkWriteDrive(): Promise<void> {
    const missing = this.unread(this.shown).length;
    if (missing && !(await this.runBulk("Reading", missing, (signal, progress) => this.readMissing(signal, progress)))) return;
    const list = this.toDrive();
    if (list.length === 0) {
      toast("The drive already holds every project value shown", "ok");
      return;
    }
    void this.runBulk("Writing", list.length, async (signal, progress) => {
      const failures: string[] = [];
      for (const [position, entry] of list.entries()) {
        if (signal.aborted) return;
        const value = this.project.get(entry.key)!.value;
        if (value === null) continue;
        try {
          this.drive.set(entry.key, { raw: await this.sources.drive!.write(entry, value) });
        } catch (error) {
          failures.push(`${address(entry)}: ${errorText(error)}`);
        }
        progress(position + 1);
      }
      if (failures.length) toast(`${failures.length} writes refused: ${failures.slice(0, 3).join("; ")}`, "error");
      else toast(`${list.length} values written to the drive`, "ok");
    });
  }

  private async bulkToProject(): Promise<void> {
    const missing = this.unread(this.shown).length;
    if (missing && !(await this.runBulk("Reading", missing, (signal, progress) => this.readMissing(signal, progress)))) return;
    const list = this.toProject();
    if (list.length === 0) {
      toast("The project already holds every drive value shown", "ok");
      return;
    }
    void this.runBulk("Storing", list.length, async (_signal, progress) => {
      const candidates = list.map((entry) => ({ entry, raw: this.drive.get(entry.key)!.raw }));
      const changes = candidates.filter((change): change is { entry: Entry; raw: number | string } =>
        unstorableReason(change.entry.variable, change.raw) === null);
      const refused = candidates.length - changes.length;
      if (changes.length) this.setProjectRows(await this.sources.project!.write(changes));
      progress(list.length);
      toast(`${changes.length} drive values stored in the project${refused ? `; ${refused} the project cannot hold (out of range or blank text)` : ""}`, refused ? "error" : "ok");
    });
  }

  private async bulkReset(list: Entry[]): Promise<void> {
    const ok = await confirmAction("Reset to defaults",
      `Remove ${list.length} values from the project files? They fall back to the dictionary defaults.`, "Reset", true);
    if (!ok) return;
    void this.runBulk("Resetting", list.length, async (_signal, progress) => {
      this.setProjectRows(await this.sources.project!.reset(list));
      progress(list.length);
    });
  }

  // ---- detail pane --------------------------------------------------------------------------------------------

  private renderDetail(): void {
    const entry = this.selected;
    if (!entry) {
      replaceChildren(this.detail, h("div", { class: "empty-state" }, this.shown.length ? "Select an entry." : "No entry matches the search."));
      return;
    }
    const variable = entry.variable;
    const driveCell = this.drive.get(entry.key);
    const projectRow = this.project.get(entry.key);
    const kv = (label: string, value: Node | string) => h("tr", null, h("td", null, label), h("td", null, value));
    const facts = h("table", { class: "kv" }, h("tbody", null,
      kv("Type", `${variable.data_type}, ${variable.access}${variable.pdo_mappable ? ", PDO mappable" : ""}`),
      kv("Range", formatRange(variable) || "—"),
      kv("Default", variable.default === null ? "none" : `${formatValue(variable, variable.default)} ${variable.unit}`.trim()),
      variable.scale !== 1 || variable.offset !== 0
        ? kv("Scaling", `physical = raw × ${variable.scale}${variable.offset ? ` + ${variable.offset}` : ""}`) : null,
      kv("Saved in", variable.save_type === "NONE" ? "not saved" : `${variable.save_type}.TXT`),
      kv("Group", entryGroup(entry) || "—"),
      variable.reference ? kv("Manual", variable.reference) : null,
    ));
    const values = h("table", { class: "kv" }, h("tbody", null,
      this.sources.drive ? kv("Drive", driveCell?.error ? h("span", { class: "error-text" }, driveCell.error)
        : driveCell ? h("span", { class: "mono", "data-testid": "detail-drive-value" }, `${formatValue(variable, driveCell.raw)} ${variable.unit}`.trim() + rawSuffix(variable, driveCell.raw))
        : this.sources.drive.online() ? "reading…" : "drive offline") : null,
      this.sources.project ? kv("Project", projectRow
        ? h("span", { class: "mono", "data-testid": "detail-project-value" }, projectRow.value === null ? h("span", { class: "muted" }, "not set, no default") : `${formatValue(variable, projectRow.value)} ${variable.unit}`.trim(), projectRow.value === null ? null : h("span", { class: "muted" }, projectRow.file ? ` (${projectRow.file})` : " (default)"))
        : "—") : null,
    ));
    replaceChildren(this.detail, h("div", { class: "panel-body" },
      h("div", { class: "mono muted" }, `${address(entry)}  ·  ${entry.object.name}`),
      h("h3", { "data-testid": "detail-name" }, variable.name),
      variable.description ? h("div", { class: "desc" }, variable.description) : null,
      h("section", null, values),
      this.keptEditor(entry),
      variable.bits.length ? this.bitsSection(entry, driveCell?.raw ?? projectRow?.value ?? null) : null,
      Object.keys(variable.enum).length ? this.enumSection(entry, driveCell?.raw ?? projectRow?.value ?? null) : null,
      variable.is_pointer ? this.pointerInfo(driveCell?.raw ?? projectRow?.value ?? null) : null,
      h("section", null, facts),
    ));
  }

  /**
   * The editor survives re-renders of the detail pane (values arriving, project rows reloaded) while the user has
   * typed into it or it shows a message, so neither the input nor an error disappears under the user's eyes.
   */
  private keptEditor(entry: Entry): HTMLElement | null {
    const previous = this.editor;
    if (previous && this.editorKey === entry.key && previous.dataset.keep === "1") return previous;
    this.editor = this.editorSection(entry);
    this.editorKey = entry.key;
    return this.editor;
  }

  private editorSection(entry: Entry): HTMLElement | null {
    const variable = entry.variable;
    const driveWritable = Boolean(this.sources.drive?.online()) && isWritable(variable.access);
    const projectWritable = Boolean(this.sources.project && this.project.get(entry.key)?.editable);
    if (!driveWritable && !projectWritable) {
      const reason = this.project.get(entry.key)?.not_editable_reason;
      return h("section", { class: "muted" }, isWritable(variable.access)
        ? (this.sources.drive || this.sources.project ? reason ?? "The drive is offline." : "Open an axis to edit values.")
        : `Read-only (${variable.access}).`);
    }
    const current = this.drive.get(entry.key)?.raw ?? this.project.get(entry.key)?.value ?? variable.default;
    const status = h("div", { "data-status": "", class: "muted" });
    let input: HTMLInputElement | HTMLSelectElement;
    const options = enumOptions(variable);
    if (options.length && valueKind(variable.data_type) === "integer") {
      input = h("select", { "data-editor": "", "data-testid": "param-editor", "aria-label": "New value" },
        options.map((option) => h("option", { value: String(option.value) }, `${option.text} (${option.value})`)));
      if (current !== null && !options.some((option) => option.value === current)) {
        input.prepend(h("option", { value: String(current) }, `${current} (not in the list)`));
      }
      input.value = current === null ? String(options[0].value) : String(current);
    } else {
      input = h("input", { type: "text", "data-editor": "", "data-testid": "param-editor", "aria-label": "New value",
        value: editText(variable, current), spellcheck: "false", autocomplete: "off", inputmode: "decimal" });
    }
    const submit = () => {
      const parsed = parseValue(variable, input.value);
      if (!parsed.ok) {
        section.dataset.keep = "1";
        input.classList.add("invalid");
        status.className = "error-text";
        status.textContent = parsed.error;
        status.dataset.testid = "param-error";
        return;
      }
      input.classList.remove("invalid");
      void this.writeValue(entry, parsed.raw, status);
    };
    const section = h("section");
    input.addEventListener("input", () => (section.dataset.keep = "1"));
    input.addEventListener("keydown", (event) => {
      if ((event as KeyboardEvent).key === "Enter") {
        event.preventDefault();
        submit();
      } else if ((event as KeyboardEvent).key === "Escape") {
        this.list.element.focus();
      }
    });
    const targets = this.targets();
    const driveBox = h("input", { type: "checkbox", disabled: !driveWritable, "data-testid": "target-drive" });
    driveBox.checked = targets.drive && driveWritable;
    const projectBox = h("input", { type: "checkbox", disabled: !projectWritable, "data-testid": "target-project" });
    projectBox.checked = targets.project && projectWritable;
    const saveTargets = () => this.setTargets({ drive: driveBox.checked, project: projectBox.checked });
    driveBox.addEventListener("change", saveTargets);
    projectBox.addEventListener("change", saveTargets);
    section.append(
      h("div", { class: "editor" }, input, variable.unit && !(variable.bits.length || variable.is_pointer) ? h("span", { class: "muted" }, variable.unit) : null,
        h("button", { class: "primary", "data-testid": "param-write", onclick: submit }, "Write")),
      h("div", { class: "toolbar", style: { marginTop: "6px" } },
        this.sources.drive ? h("label", { class: "check" }, driveBox, "to drive") : null,
        this.sources.project ? h("label", { class: "check" }, projectBox, "to project") : null),
      status);
    return section;
  }

  private bitsSection(entry: Entry, raw: Scalar): HTMLElement {
    const variable = entry.variable;
    const word = typeof raw === "number" ? raw : 0;
    const editable = isWritable(variable.access) && (Boolean(this.sources.drive?.online()) || Boolean(this.project.get(entry.key)?.editable));
    const cells: Node[] = [];
    for (const field of decodeBits(word, variable.bits)) {
      const single = field.first === field.last;
      let control: Node = h("span", { class: field.value ? "on" : "" }, String(field.value));
      if (editable && single) {
        const box = h("input", { type: "checkbox", title: `Toggle bit ${field.first}` });
        box.checked = field.value === 1;
        box.addEventListener("change", () => {
          const input = this.detail.querySelector<HTMLInputElement>("input[data-editor]");
          if (!input) return;
          const parsed = parseValue(variable, input.value);
          const base = parsed.ok && typeof parsed.raw === "number" ? parsed.raw : word;
          input.value = formatHex(insertBits(base, field.first, field.last, box.checked ? 1 : 0), hexWidth(variable.data_type));
          input.dispatchEvent(new Event("input"));
        });
        control = box;
      }
      cells.push(h("span", { class: "mono muted" }, fieldLabel(field)), h("span", { class: field.value ? "on" : "" }, field.name), control);
    }
    return h("section", null, h("div", { class: "muted", style: { marginBottom: "4px" } }, editable ? "Bits (tick, then Write)" : "Bits"), h("div", { class: "bits" }, cells));
  }

  private enumSection(entry: Entry, raw: Scalar): HTMLElement {
    return h("section", null, h("div", { class: "muted", style: { marginBottom: "4px" } }, "Values"),
      h("div", { class: "enum-list" }, enumOptions(entry.variable).map((option) => [
        h("span", { class: `mono ${option.value === raw ? "current" : ""}` }, String(option.value)),
        h("span", { class: option.value === raw ? "current" : "" }, option.text),
      ])));
  }

  /** Pointer: show the target symbolically and offer a picker over the PDO-mappable entries of the dictionary. */
  private pointerInfo(raw: Scalar): HTMLElement {
    const target = typeof raw === "number" && raw > 0 ? decodePointer(raw) : null;
    const targetEntry = target ? this.byKey.get(`${target.index}.${target.subindex}`) : undefined;
    const picker = h("select", { "data-testid": "pointer-picker", "aria-label": "Pointer target" },
      h("option", { value: "" }, "Link to…"),
      this.entryList.filter((entry) => entry.variable.pdo_mappable).map((entry) =>
        h("option", { value: entry.key }, `${address(entry)} ${entry.variable.name}`)));
    const bit = h("input", { type: "text", value: String(target?.bit ?? 0), style: { width: "52px" }, "aria-label": "Bit or size" });
    const apply = () => {
      const chosen = this.byKey.get(picker.value);
      const bitValue = Number(bit.value);
      const input = this.detail.querySelector<HTMLInputElement>("input[data-editor]");
      if (!chosen || !input || !Number.isInteger(bitValue) || bitValue < 0 || bitValue > 255) return;
      input.value = formatHex(encodePointer({ index: chosen.object.index, subindex: chosen.variable.subindex, bit: bitValue }), 8);
      input.dispatchEvent(new Event("input"));
    };
    picker.addEventListener("change", apply);
    bit.addEventListener("input", apply);
    if (targetEntry) picker.value = targetEntry.key;
    return h("section", null,
      h("div", null, h("span", { class: "muted" }, "Points to "), typeof raw === "number" ? formatPointer(raw) : "—",
        targetEntry ? h("span", null, ` · ${targetEntry.variable.name}`) : null),
      h("div", { class: "editor", style: { marginTop: "6px" } }, picker, h("span", { class: "muted" }, "bit/size"), bit));
  }
}

function entryGroup(entry: Entry): string {
  return entry.variable.group || entry.object.group;
}

function rawSuffix(variable: Entry["variable"], raw: Scalar): string {
  if (typeof raw !== "number") return "";
  if (variable.scale !== 1 || variable.offset !== 0) return `  (raw ${raw})`;
  return "";
}
