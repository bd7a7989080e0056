/**
 * Bulk actions on the shown rows — Refresh, Write changed → drive, Drive → project, Reset to defaults — and the
 * progress bar with Cancel that replaces their buttons while one runs.
 */

import type { ProjectParameter } from "../../client/api";
import { confirmAction, errorText, toast } from "../ui";
import { derive, h, state, untrack, type State } from "../../lib/dom";
import { address, isReadable, type Entry, type Scalar } from "../../lib/od";
import { formatValue, unstorableReason } from "../../lib/values";
import { confirmChanges, type Change } from "../confirm/changes";
import type { ParameterStore } from "./store";

export interface BulkSources {
  drive: null | { write(entry: Entry, raw: number | string): Promise<Scalar> };
  project: null | {
    write(changes: { entry: Entry; raw: number | string }[]): Promise<ProjectParameter[]>;
    reset(entries: Entry[]): Promise<ProjectParameter[]>;
  };
}

export interface BulkProgress {
  label: string;
  total: number;
  done: State<number>;
  controller: AbortController;
}

type Work = (signal: AbortSignal, progress: (done: number) => void) => Promise<void>;

export class BulkActions {
  readonly element: HTMLElement;
  readonly running = state<BulkProgress | null>(null);
  private readonly toDrive: State<Entry[]>;
  private readonly toProject: State<Entry[]>;
  private readonly explicit: State<Entry[]>;
  /** Entries the project files set that the filter hides: Write changed → drive leaves them out. */
  private readonly hidden: State<Entry[]>;
  /** Differences are known for the entries read so far; "+" says unread entries may add some (read on click). */
  private readonly more: State<string>;

  constructor(
    private readonly store: ParameterStore,
    private readonly sources: BulkSources,
    private readonly shown: State<Entry[]>,
    all: Entry[] = [],
  ) {
    this.toDrive = derive(() => store.toDrive(shown.val));
    this.toProject = derive(() => store.toProject(shown.val));
    this.explicit = derive(() => store.explicit(shown.val));
    this.hidden = derive(() => {
      const visible = new Set(shown.val);
      return store.explicit(all).filter((entry) => !visible.has(entry));
    });
    this.more = derive(() => (store.online.val && store.unread(shown.val).length > 0 ? "+" : ""));
    this.element = h("span", { class: "toolbar" }, () => {
      const running = this.running.val;
      return untrack(() => (running ? progressView(running) : this.buttons()));
    });
  }

  /** Run a long operation with a progress bar and a Cancel button in place of the buttons; true when it completed. */
  async run(label: string, total: number, work: Work): Promise<boolean> {
    const controller = new AbortController();
    const done = state(0);
    this.running.val = { label, total, done, controller };
    try {
      await work(controller.signal, (count) => (done.val = count));
      if (controller.signal.aborted) toast(`${label}: cancelled`);
      return !controller.signal.aborted;
    } catch (error) {
      toast(`${label}: ${errorText(error)}`, "error");
      return false;
    } finally {
      this.running.val = null;
    }
  }

  /** Read the drive values a comparison needs but has not yet (rows never scrolled into view); true when complete. */
  async readMissing(list: Entry[]): Promise<boolean> {
    const missing = this.store.unread(list);
    if (!this.sources.drive || missing.length === 0 || !this.store.online.rawVal) return true;
    return this.run("Reading", missing.length, (signal, progress) => this.store.read(missing, signal, progress));
  }

  private buttons(): HTMLElement[] {
    const { store, sources } = this;
    const offline = () => !store.online.val;
    const buttons: HTMLElement[] = [];
    if (sources.drive) {
      buttons.push(h("button", {
        disabled: () => offline() || this.shown.val.length === 0, title: "Read the shown entries from the drive again",
        "data-testid": "param-refresh", onclick: () => void this.refresh(),
      }, "Refresh"));
    }
    if (sources.drive && sources.project) {
      buttons.push(h("button", {
        disabled: () => offline() || (this.toDrive.val.length === 0 && !this.more.val), "data-testid": "param-write-changed",
        title: "Write the shown project values that differ from the drive into the drive, after you confirmed the list"
          + " (unread entries are read first; rows the filter hides are not written)",
        onclick: () => void this.writeToDrive(),
      }, () => `Write changed → drive (${this.toDrive.val.length}${this.more.val})`),
      h("span", { class: "muted", "data-testid": "param-hidden-note" },
        () => (this.hidden.val.length ? `shown rows only: the filter hides ${this.hidden.val.length} set values` : "")),
      h("button", {
        disabled: () => this.toProject.val.length === 0 && !this.more.val, "data-testid": "param-revert",
        title: "Take the drive values of the differing entries into the project (unread entries are read first)",
        onclick: () => void this.driveToProject(),
      }, () => `Drive → project (${this.toProject.val.length}${this.more.val})`));
    }
    if (sources.project) {
      buttons.push(h("button", {
        disabled: () => this.explicit.val.length === 0, "data-testid": "param-reset",
        title: "Remove the shown values from the project files: they fall back to the defaults",
        onclick: () => void this.reset(this.explicit.rawVal),
      }, () => `Reset to defaults (${this.explicit.val.length})`));
    }
    return buttons;
  }

  private async refresh(): Promise<void> {
    const list = this.shown.rawVal.filter((entry) => isReadable(entry.variable.access));
    this.store.forget(list);
    await this.run("Reading", list.length, (signal, progress) => this.store.read(list, signal, progress));
  }

  private async writeToDrive(): Promise<void> {
    // The hidden values the project sets are read too, so the confirmation can say how many of them differ.
    if (!(await this.readMissing([...this.shown.rawVal, ...this.hidden.rawVal]))) return;
    const list = this.toDrive.rawVal;
    if (list.length === 0) {
      toast("The drive already holds every project value shown", "ok");
      return;
    }
    if (!(await this.confirmWrite(list))) return;
    await this.run("Writing", list.length, async (signal, progress) => {
      const failures: string[] = [];
      for (const [position, entry] of list.entries()) {
        if (signal.aborted) return;
        const value = this.store.projectRow(entry.key).rawVal?.value ?? null;
        if (value === null) continue;
        try {
          this.store.driveCell(entry.key).val = { raw: await this.sources.drive!.write(entry, value) };
        } catch (error) {
          failures.push(`${address(entry)}: ${errorText(error)}`);
        }
        progress(position + 1);
      }
      if (failures.length) toast(`${failures.length} writes refused: ${failures.slice(0, 3).join("; ")}`, "error");
      else toast(`${list.length} values written to the drive`, "ok");
    });
  }

  /** The list of what goes to the drive (drive value → project value), and what the filter keeps out of it. */
  private confirmWrite(list: Entry[]): Promise<boolean> {
    const changes: Change[] = list.map((entry) => ({
      address: address(entry), name: entry.variable.name,
      old: shownValue(entry, this.store.driveCell(entry.key).rawVal?.raw), new: shownValue(entry, this.store.projectRow(entry.key).rawVal?.value),
    }));
    const hidden = this.hidden.rawVal;
    const differing = this.store.toDrive(hidden).length;
    const notes = hidden.length
      ? [`The filter hides ${hidden.length} more entries the project sets${differing ? ` (${differing} of them differ from the drive)` : ""}: they are not written. Clear the search and the group to write them too.`]
      : ["Every entry the project sets is shown: nothing is hidden by the filter."];
    return confirmChanges({
      title: "Write changed values to the drive", confirm: `Write ${list.length} to the drive`, danger: true, changes, notes,
      text: `Write ${list.length} project values into the drive? The drive acts on each at once (drive value → project value):`,
    });
  }

  /** The project values Drive → project replaces (project value → drive value). */
  private confirmTake(list: Entry[]): Promise<boolean> {
    const changes: Change[] = list.map((entry) => ({
      address: address(entry), name: entry.variable.name,
      old: shownValue(entry, this.store.projectRow(entry.key).rawVal?.value), new: shownValue(entry, this.store.driveCell(entry.key).rawVal?.raw),
    }));
    return confirmChanges({
      title: "Take drive values into the project", confirm: `Store ${list.length} in the project`, changes, folded: list.length > 20,
      text: `Store ${list.length} drive values in the project (project value → drive value)?`,
      notes: ["The project as it is now is kept as a revision: the backup page can restore it."],
    });
  }

  private async driveToProject(): Promise<void> {
    if (!(await this.readMissing(this.shown.rawVal))) return;
    const list = this.toProject.rawVal;
    if (list.length === 0) {
      toast("The project already holds every drive value shown", "ok");
      return;
    }
    if (!(await this.confirmTake(list))) return;
    await this.run("Storing", list.length, async (_signal, progress) => {
      const candidates = list.map((entry) => ({ entry, raw: this.store.driveCell(entry.key).rawVal!.raw }));
      const changes = candidates.filter((change): change is { entry: Entry; raw: number | string } =>
        unstorableReason(change.entry.variable, change.raw) === null);
      const refused = candidates.length - changes.length;
      if (changes.length) this.store.setProjectRows(await this.sources.project!.write(changes));
      progress(list.length);
      toast(`${changes.length} drive values stored in the project${refused ? `; ${refused} the project cannot hold (out of range or blank text)` : ""}`, refused ? "error" : "ok");
    });
  }

  private async reset(list: Entry[]): Promise<void> {
    const ok = await confirmAction("Reset to defaults",
      `Remove ${list.length} values from the project files? They fall back to the dictionary defaults.`, "Reset", true);
    if (!ok) return;
    await this.run("Resetting", list.length, async (_signal, progress) => {
      this.store.setProjectRows(await this.sources.project!.reset(list));
      progress(list.length);
    });
  }
}

function shownValue(entry: Entry, raw: Scalar | undefined): string {
  return `${formatValue(entry.variable, raw ?? null)} ${entry.variable.unit}`.trim();
}

function progressView(running: BulkProgress): (Node | string)[] {
  const { label, total, done, controller } = running;
  return [
    h("span", { class: "muted" }, () => `${label} ${done.val}/${total}`),
    h("progress", { max: String(Math.max(1, total)), value: () => String(done.val), style: { width: "160px" } }),
    h("button", { "data-testid": "bulk-cancel", onclick: () => controller.abort() }, "Cancel"),
  ];
}
