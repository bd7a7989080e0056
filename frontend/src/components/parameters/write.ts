/**
 * Writing one value: the entry's editor with its Write button, the targets (to drive / to project, remembered in
 * the browser) and the status line under them (the check's or the server's refusal, or what was written).
 */

import { errorText } from "../ui";
import { valueEditor, type ValueEditor } from "../editors";
import { derive, h, state, untrack, type State } from "../../lib/dom";
import { address, isWritable, type Entry } from "../../lib/od";
import { formatValue } from "../../lib/values";
import type { ParameterStore } from "./store";

const TARGETS_KEY = "servostudio.writeTargets";

export interface Targets {
  drive: boolean;
  project: boolean;
}

/** The chosen targets, stored in the browser; what they resolve to depends on what is there (`resolve`). */
export class WriteTargets {
  private readonly stored: State<Targets>;

  constructor(
    private readonly store: ParameterStore,
    private readonly hasDrive: boolean,
    private readonly hasProject: boolean,
  ) {
    const text = localStorage.getItem(TARGETS_KEY);
    this.stored = state(text ? (JSON.parse(text) as Targets) : { drive: true, project: true });
  }

  /** The targets a write goes to: the chosen ones that are there, else whichever is. */
  resolve(): Targets {
    const driveOk = this.hasDrive && this.store.online.val;
    const chosen = this.stored.val;
    const result = { drive: driveOk && chosen.drive, project: this.hasProject && chosen.project };
    if (!result.drive && !result.project) return { drive: driveOk, project: !driveOk && this.hasProject };
    return result;
  }

  save(targets: Targets): void {
    localStorage.setItem(TARGETS_KEY, JSON.stringify(targets));
    this.stored.val = targets;
  }
}

export interface WriteContext {
  store: ParameterStore;
  targets: WriteTargets;
  hasDrive: boolean;
  hasProject: boolean;
  /** Write to the resolved targets; the names of those written. */
  write(entry: Entry, raw: number | string): Promise<string[]>;
  /** Escape in the editor. */
  leave(): void;
}

interface Status {
  tone: "muted" | "error-text" | "ok-text";
  text: string;
}

/** Why the entry cannot be edited here (read-only, offline, not in the project), or null. */
export function notEditableReason(entry: Entry, context: WriteContext, canDrive: boolean, canProject: boolean): string | null {
  if (canDrive || canProject) return null;
  if (!isWritable(entry.variable.access)) return `Read-only (${entry.variable.access}).`;
  if (!context.hasDrive && !context.hasProject) return "Open an axis to edit values.";
  return context.store.projectRow(entry.key).rawVal?.not_editable_reason ?? "The drive is offline.";
}

/**
 * The editor section for `entry`: a bound child showing the editor, the targets and the status line where the entry
 * can be written (drive online and writable, or editable in the project), else why not. The editor and the status
 * line are made once: when the entry becomes writable somewhere else, they move into the new section with what the
 * user typed and the last message. `editor` is the editor while it is shown (the bit and pointer pickers write into it).
 */
export function writeSection(entry: Entry, context: WriteContext, canDrive: State<boolean>, canProject: State<boolean>): { section: () => HTMLElement; editor: State<ValueEditor | null> } {
  const variable = entry.variable;
  const status = state<Status>({ tone: "muted", text: "" });
  const write = async (raw: number | string) => {
    status.val = { tone: "muted", text: "Writing…" };
    try {
      const done = await context.write(entry, raw);
      editor.revert();
      status.val = done.length
        ? { tone: "ok-text", text: `${address(entry)} = ${formatValue(variable, raw)} written to ${done.join(" and ")}` }
        : { tone: "error-text", text: "Nothing to write to" };
    } catch (error) {
      status.val = { tone: "error-text", text: errorText(error) };
    }
  };
  const editor = valueEditor(variable, {
    value: () => context.store.current(entry),
    onEscape: () => context.leave(),
    onSubmit: (raw) => void write(raw),
    onRefuse: (reason) => (status.val = { tone: "error-text", text: reason }),
    attrs: { "data-editor": "", "data-testid": "param-editor", "aria-label": "New value" },
  });
  const row = h("div", { class: "editor" }, editor.element,
    variable.unit && !(variable.bits.length || variable.is_pointer) ? h("span", { class: "muted" }, variable.unit) : null,
    h("button", { class: "primary", "data-testid": "param-write", onclick: () => editor.submit() }, "Write"));
  const statusLine = h("div", {
    "data-status": "", class: () => status.val.tone,
    "data-testid": () => (status.val.tone === "error-text" ? "param-error" : false),
  }, () => status.val.text);
  const section = () => {
    const [toDrive, toProject] = [canDrive.val, canProject.val];
    return untrack(() => {
      const reason = notEditableReason(entry, context, toDrive, toProject);
      if (reason !== null) return h("section", { class: "muted" }, reason);
      return h("section", null, row, targetBoxes(context, toDrive, toProject), statusLine);
    });
  };
  return { section, editor: derive(() => (canDrive.val || canProject.val ? editor : null)) };
}

/** to drive / to project: checked as the targets resolve, disabled where this entry cannot be written. */
function targetBoxes(context: WriteContext, canDrive: boolean, canProject: boolean): HTMLElement {
  const resolved = derive(() => context.targets.resolve());
  const save = () => context.targets.save({ drive: driveBox.checked, project: projectBox.checked });
  const driveBox: HTMLInputElement = h("input", {
    type: "checkbox", disabled: !canDrive, "data-testid": "target-drive", checked: () => resolved.val.drive && canDrive, onchange: save,
  });
  const projectBox: HTMLInputElement = h("input", {
    type: "checkbox", disabled: !canProject, "data-testid": "target-project", checked: () => resolved.val.project && canProject, onchange: save,
  });
  return h("div", { class: "toolbar", style: { marginTop: "6px" } },
    context.hasDrive ? h("label", { class: "check" }, driveBox, "to drive") : null,
    context.hasProject ? h("label", { class: "check" }, projectBox, "to project") : null);
}
