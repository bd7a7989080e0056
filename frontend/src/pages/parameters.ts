/**
 * Parameter editor: every object of a dictionary in the manual's groups, searchable, with the drive value, the
 * project value and the default side by side. Used for an axis (drive + project) and for a bare dictionary.
 *
 * Composed of the toolbar (search, group, Only differences, count), the virtualised table, the bulk actions and
 * the detail pane with the value editor (`components/parameters/`). The filter, the selection and every value
 * are states; the parts bind to them.
 */

import type { ProjectParameter } from "../client/api";
import { BulkActions } from "../components/parameters/bulk";
import { detailPane } from "../components/parameters/detail";
import { ALL_GROUPS, APPLICATION_GROUPS, filterEntries, rowsOf, type Row } from "../components/parameters/rows";
import { ParameterStore, type DriveCell } from "../components/parameters/store";
import { ParameterTable } from "../components/parameters/table";
import { parameterToolbar } from "../components/parameters/toolbar";
import { LiveValues, type Watcher } from "../components/parameters/live";
import { WriteTargets, type Targets } from "../components/parameters/write";
import { errorText, toast } from "../components/ui";
import { Scope, batch, derive, h, state, untrack, type State } from "../lib/dom";
import { entries as allEntries, isReadable, type Dictionary, type Entry, type Scalar } from "../lib/od";
import type { Location } from "../lib/router";
import { buildIndex, type Searchable } from "../lib/search";

export type { DriveCell } from "../components/parameters/store";

/** Where values come from and go to; either side may be absent (bare dictionary, offline axis). */
export interface ParameterSources {
  drive: null | {
    online(): boolean;
    read(entries: Entry[], signal: AbortSignal): Promise<Map<string, DriveCell>>;
    write(entry: Entry, raw: number | string): Promise<Scalar>;
    /** Follow these entries' drive values (the server samples them); an empty list stops. */
    watch?: Watcher;
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

/** `?group=*`: every group, although the axis has an application template (Expert mode). */
const EXPERT_QUERY = "*";
const READ_DEBOUNCE_MS = 120;

export class ParameterEditor {
  readonly element: HTMLElement;
  private readonly scope = new Scope();
  private readonly entryList: Entry[];
  private readonly byKey = new Map<string, Entry>();
  private readonly index: Searchable[];
  private readonly store: ParameterStore;
  private readonly targets = new WriteTargets();
  private readonly live: LiveValues;
  private readonly applicationGroups: Set<string>;
  private readonly text: State<string>;
  private readonly group: State<string>;
  private readonly onlyDiff = state(false);
  /** While the values Only differences needs are read, every entry of the filter is shown. */
  private readonly readingForDiff = state(false);
  private readonly selected = state<Entry | null>(null);
  private readonly shown: State<Entry[]>;
  private readonly rows: State<Row[]>;
  private readonly table: ParameterTable;
  private readonly bulk: BulkActions;
  private readonly search: HTMLInputElement;
  private readonly pendingReads = new Set<string>();
  private readonly abort = new AbortController();
  private readTimer = 0;

  constructor(
    private readonly dictionary: Dictionary,
    private readonly sources: ParameterSources,
    location: Location,
  ) {
    this.entryList = allEntries(dictionary);
    for (const entry of this.entryList) this.byKey.set(entry.key, entry);
    this.index = buildIndex(this.entryList);
    this.applicationGroups = new Set(sources.application?.groups ?? []);
    const drive = sources.drive;
    this.store = new ParameterStore(Boolean(drive?.online()), drive ? (list, signal) => drive.read(list, signal) : null);
    this.live = new LiveValues(this.store, drive?.watch ?? null);
    this.text = state(location.query.q ?? "");
    this.group = state(this.initialGroup(location.query.group));
    const view = this.scope.run(() => derive(() => this.filter()));
    this.shown = this.scope.run(() => derive(() => view.val.shown));
    this.rows = this.scope.run(() => derive(() => view.val.rows));
    this.bulk = this.scope.run(() => new BulkActions(this.store, sources, this.shown, this.entryList));
    this.table = new ParameterTable({
      store: this.store, rows: this.rows, selected: this.selected,
      hasDrive: sources.drive !== null, hasProject: sources.project !== null,
      onVisible: (rows) => this.scheduleRead(rows),
      onSelect: (key) => this.select(this.byKey.get(key)!, false),
      onKey: (event) => this.onTableKey(event),
      onOpen: () => this.focusEditor(),
    });
    const toolbar = this.scope.run(() => this.toolbar());
    this.search = toolbar.search;
    this.element = this.scope.run(() => h("div", { class: "page fill" }, toolbar.element,
      h("div", { class: "params" }, this.table.element, this.detail())));
    this.follow();
  }

  /** Load the project values (rows are shown already; drive values are read as rows come into view). */
  async start(): Promise<void> {
    if (!this.sources.project) return;
    try {
      this.store.setProjectRows(await this.sources.project.load());
    } catch (error) {
      toast(`Project values: ${errorText(error)}`, "error");
    }
  }

  dispose(): void {
    this.abort.abort();
    this.live.stop();
    this.bulk.running.rawVal?.controller.abort();
    clearTimeout(this.readTimer);
    this.scope.dispose();
    this.table.dispose();
  }

  /** The drive went on- or offline: the parts bound to it follow; Only differences compares again. */
  onlineChanged(): void {
    this.store.online.val = Boolean(this.sources.drive?.online());
    if (this.onlyDiff.rawVal && this.store.online.rawVal && !this.bulk.running.rawVal) {
      this.readingForDiff.val = true;
      void this.readForDiff();
    }
  }

  focusSearch(): boolean {
    this.search.focus();
    this.search.select();
    return true;
  }

  /** Query-only URL change (back/forward between searches): update the filter in place. */
  update(location: Location): boolean {
    batch(() => {
      this.text.val = location.query.q ?? "";
      this.group.val = this.initialGroup(location.query.group);
    });
    return true;
  }

  // ---- filter -------------------------------------------------------------------------------------------------

  /** The group from the URL when it names one; else the application's groups when a template is chosen. */
  private initialGroup(fromUrl: string | undefined): string {
    if (fromUrl === EXPERT_QUERY) return ALL_GROUPS;
    if (fromUrl !== undefined && this.dictionary.groups.includes(fromUrl)) return fromUrl;
    return this.applicationGroups.size > 0 ? APPLICATION_GROUPS : ALL_GROUPS;
  }

  /** The URL form of a group choice: the default (the application's groups, or all without one) is left out. */
  private groupQuery(group: string): string | undefined {
    if (group === APPLICATION_GROUPS) return undefined;
    if (group === ALL_GROUPS) return this.applicationGroups.size > 0 ? EXPERT_QUERY : undefined;
    return group;
  }

  /**
   * The entries and rows of the current filter. Re-computed when the search, the group or Only differences change;
   * the differences are taken as known at that moment (values read later do not make rows jump).
   */
  private filter(): { shown: Entry[]; rows: Row[] } {
    const text = this.text.val;
    const group = this.group.val;
    const onlyDiff = this.onlyDiff.val && !this.readingForDiff.val;
    return untrack(() => {
      const only = onlyDiff ? (entry: Entry) => this.store.differs(entry) : null;
      const shown = filterEntries(this.index, { text, group, applicationGroups: this.applicationGroups, only });
      return { shown, rows: rowsOf(this.dictionary, shown, text.trim() !== "") };
    });
  }

  private setOnlyDiff(checked: boolean): void {
    const read = checked && this.store.online.rawVal && this.sources.drive !== null;
    batch(() => {
      this.onlyDiff.val = checked;
      if (read) this.readingForDiff.val = true;
    });
    if (read) void this.readForDiff();
  }

  /** "Only differences" compares every shown entry: read the missing drive values first, then filter. */
  private async readForDiff(): Promise<void> {
    const complete = await this.bulk.readMissing(this.shown.rawVal);
    batch(() => {
      this.readingForDiff.val = false;
      if (!complete) this.onlyDiff.val = false;
    });
  }

  // ---- parts --------------------------------------------------------------------------------------------------

  private toolbar(): { element: HTMLElement; search: HTMLInputElement } {
    return parameterToolbar({
      dictionary: this.dictionary, application: this.sources.application ?? null,
      text: this.text, group: this.group, onlyDiff: this.onlyDiff, shown: this.shown, total: this.entryList.length,
      compare: this.sources.drive !== null && this.sources.project !== null,
      onQuery: () => this.sources.onQuery({ q: this.text.rawVal.trim() || undefined, group: this.groupQuery(this.group.rawVal) }),
      onOnlyDiff: (checked) => this.setOnlyDiff(checked),
      onEnterTable: () => {
        this.moveSelection(0, true);
        this.table.focus();
      },
      bulk: this.bulk.element,
    });
  }

  private detail(): HTMLElement {
    return detailPane({
      store: this.store, targets: this.targets, selected: this.selected, shown: this.shown, entries: this.entryList,
      hasDrive: this.sources.drive !== null, hasProject: this.sources.project !== null,
      write: (entry, raw, targets) => this.writeValue(entry, raw, targets),
      leave: () => this.table.focus(),
    });
  }

  /** The table follows the rows; a filter that hides the selection selects its first entry; online reads the view. */
  private follow(): void {
    this.scope.add(this.table.follow());
    this.scope.effect(() => {
      const found = this.shown.val;
      untrack(() => {
        const selected = this.selected.val;
        if (found.length > 0 && (!selected || !found.includes(selected))) this.select(found[0], false);
      });
    });
    this.scope.effect(() => {
      const online = this.store.online.val;
      untrack(() => (online ? this.scheduleRead(this.table.visible) : this.watchLive()));
    });
    this.scope.effect(() => {
      const selected = this.selected.val;
      untrack(() => this.watchLive(selected));
    });
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
    const shown = this.shown.rawVal;
    if (shown.length === 0) return;
    const selected = this.selected.rawVal;
    const position = fromStart || !selected ? -1 : shown.indexOf(selected);
    this.select(shown[Math.min(shown.length - 1, Math.max(0, position + (fromStart ? 1 : step)))], true);
  }

  private select(entry: Entry, scroll: boolean): void {
    this.selected.val = entry;
    if (scroll) this.table.scrollTo(entry);
    if (this.store.online.rawVal && isReadable(entry.variable.access) && this.store.driveCell(entry.key).rawVal === undefined) {
      void this.store.read([entry], this.abort.signal);
    }
  }

  private focusEditor(): void {
    const editor = this.element.querySelector<HTMLInputElement | HTMLSelectElement>("[data-editor]");
    editor?.focus();
    if (editor instanceof HTMLInputElement) editor.select();
  }

  // ---- drive values and writing -------------------------------------------------------------------------------

  /** Read the drive values of rows that came into view and have none yet, batched and debounced. */
  private scheduleRead(rows: Row[]): void {
    this.watchLive();
    if (!this.sources.drive || !this.store.online.rawVal) return;
    for (const row of rows) {
      if (row.kind === "entry" && isReadable(row.entry.variable.access) && this.store.driveCell(row.entry.key).rawVal === undefined) {
        this.pendingReads.add(row.entry.key);
      }
    }
    clearTimeout(this.readTimer);
    this.readTimer = window.setTimeout(() => {
      const wanted = [...this.pendingReads].map((key) => this.byKey.get(key)!).filter((entry) => this.store.driveCell(entry.key).rawVal === undefined);
      this.pendingReads.clear();
      if (wanted.length) void this.store.read(wanted, this.abort.signal);
    }, READ_DEBOUNCE_MS);
  }

  /** The live entries in view and the selected one follow the drive (`LiveValues`). */
  private watchLive(selected: Entry | null = this.selected.rawVal): void {
    const inView = this.table.visible.flatMap((row) => (row.kind === "entry" ? [row.entry] : []));
    this.live.show(inView, selected);
  }

  /** Write one value to the targets the user chose (the server validates); the names of the targets written. */
  private async writeValue(entry: Entry, raw: number | string, targets: Targets): Promise<string[]> {
    const done: string[] = [];
    if (targets.drive && this.sources.drive) {
      this.store.driveCell(entry.key).val = { raw: await this.sources.drive.write(entry, raw) };
      done.push("drive");
    }
    if (targets.project && this.sources.project && entry.variable.save_type !== "NONE") {
      this.store.setProjectRows(await this.sources.project.write([{ entry, raw }]));
      done.push("project");
    }
    return done;
  }
}
