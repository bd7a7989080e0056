/**
 * Writing one value: the entry's editor with its Write button, the target (project, drive, or both) and the status
 * line under them (the check's or the server's refusal, or where the value went).
 *
 * Nothing goes to a drive without the user choosing it: an entry the project holds is written to the project unless
 * the user picks "drive" (the choice lasts while the editor is open, never across visits), and the Write button
 * names its target. The field holds the value of that target — the project's when writing to the project — so a
 * project-only write does not make the field jump back to the drive's value; both values stay in the detail pane.
 */

import { errorText } from "../ui";
import { valueEditor, type ValueEditor } from "../editors";
import { derive, h, state, untrack, type State } from "../../lib/dom";
import { address, isWritable, type Entry, type Scalar } from "../../lib/od";
import { formatValue } from "../../lib/values";
import type { ParameterStore } from "./store";

export interface Targets {
  drive: boolean;
  project: boolean;
}

export type TargetChoice = "project" | "drive" | "both";

const CHOICES: { choice: TargetChoice; label: string }[] = [
  { choice: "project", label: "project" },
  { choice: "drive", label: "drive" },
  { choice: "both", label: "drive and project" },
];

/** The target the user chose for this editor (project until they pick another); `resolve` fits it to an entry. */
export class WriteTargets {
  readonly chosen = state<TargetChoice>("project");

  /** Where a write of an entry goes: the chosen target where the entry can go there, else the one place it can. */
  resolve(canDrive: boolean, canProject: boolean): Targets {
    const choice = this.chosen.val;
    const wanted = { drive: choice !== "project" && canDrive, project: choice !== "drive" && canProject };
    if (wanted.drive || wanted.project) return wanted;
    return { drive: canDrive && !canProject, project: canProject };
  }
}

export interface WriteContext {
  store: ParameterStore;
  targets: WriteTargets;
  hasDrive: boolean;
  hasProject: boolean;
  /** Write to these targets; the names of those written. */
  write(entry: Entry, raw: number | string, targets: Targets): Promise<string[]>;
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

/** "written to the project; the drive still holds 1089" — where the value went and what the other side holds. */
export function writtenText(entry: Entry, store: ParameterStore, raw: number | string, done: string[]): string {
  const variable = entry.variable;
  const head = `${address(entry)} = ${formatValue(variable, raw)} written to the ${done.join(" and the ")}`;
  if (done.length !== 1) return head;
  const other: Scalar | undefined = done[0] === "project" ? store.driveCell(entry.key).rawVal?.raw : store.projectRow(entry.key).rawVal?.value;
  if (other === undefined || other === null) return head;
  const side = done[0] === "project" ? "drive" : "project";
  return `${head}; the ${side} ${other === raw ? "holds the same" : `still holds ${formatValue(variable, other)}`}`;
}

/**
 * The editor section for `entry`: a bound child showing the editor, the target and the status line where the entry
 * can be written (drive online and writable, or editable in the project), else why not. The editor and the status
 * line are made once: when the entry becomes writable somewhere else, they move into the new section with what the
 * user typed and the last message. `editor` is the editor while it is shown (the bit and pointer pickers write into it).
 */
export function writeSection(entry: Entry, context: WriteContext, canDrive: State<boolean>, canProject: State<boolean>): { section: () => HTMLElement; editor: State<ValueEditor | null>; holds: State<"drive" | "project"> } {
  const variable = entry.variable;
  const status = state<Status>({ tone: "muted", text: "" });
  const targets = derive(() => context.targets.resolve(canDrive.val, canProject.val));
  /** The value the field holds: the drive's when the write goes to the drive, else the project's. */
  const holds = derive<"drive" | "project">(() => (targets.val.drive ? "drive" : "project"));
  const write = async (raw: number | string) => {
    const chosen = targets.rawVal;
    status.val = { tone: "muted", text: "Writing…" };
    try {
      const done = await context.write(entry, raw, chosen);
      editor.revert();
      status.val = done.length
        ? { tone: "ok-text", text: writtenText(entry, context.store, raw, done) }
        : { tone: "error-text", text: "Nothing to write to" };
    } catch (error) {
      status.val = { tone: "error-text", text: errorText(error) };
    }
  };
  const editor = valueEditor(variable, {
    value: () => (holds.val === "drive" ? context.store.driveCell(entry.key).val?.raw : context.store.projectRow(entry.key).val?.value) ?? context.store.current(entry),
    onEscape: () => context.leave(),
    onSubmit: (raw) => void write(raw),
    onRefuse: (reason) => (status.val = { tone: "error-text", text: reason }),
    attrs: { "data-editor": "", "data-testid": "param-editor", "aria-label": "New value" },
  });
  const button = h("button", {
    class: () => (targets.val.drive ? "danger solid" : "primary"), "data-testid": "param-write", onclick: () => editor.submit(),
    title: () => (targets.val.drive ? "Writes to the live drive: it acts on the value at once" : "Writes to the project files only"),
  }, () => `Write to ${targetName(targets.val)}`);
  const row = h("div", { class: "editor" }, editor.element,
    variable.unit && !(variable.bits.length || variable.is_pointer) ? h("span", { class: "muted" }, variable.unit) : null, button);
  const statusLine = h("div", {
    "data-status": "", class: () => status.val.tone,
    "data-testid": () => (status.val.tone === "error-text" ? "param-error" : "param-status"),
  }, () => status.val.text);
  const section = () => {
    const [toDrive, toProject] = [canDrive.val, canProject.val];
    return untrack(() => {
      const reason = notEditableReason(entry, context, toDrive, toProject);
      if (reason !== null) return h("section", { class: "muted" }, reason);
      return h("section", null, row, targetChoice(context, toDrive, toProject, holds), statusLine);
    });
  };
  return { section, editor: derive(() => (canDrive.val || canProject.val ? editor : null)), holds };
}

function targetName(targets: Targets): string {
  if (targets.drive && targets.project) return "drive and project";
  return targets.drive ? "drive" : "project";
}

/** Write to: project / drive / drive and project (where both can take the entry), and what the field holds. */
function targetChoice(context: WriteContext, canDrive: boolean, canProject: boolean, holds: State<"drive" | "project">): HTMLElement {
  const holding = h("span", { class: "muted", "data-testid": "editor-holds" }, () => `The field holds the ${holds.val} value.`);
  if (!(canDrive && canProject)) {
    const only = canDrive ? "drive (the project does not hold this entry)" : "project";
    return h("div", { class: "toolbar", style: { marginTop: "6px" } }, h("span", { class: "muted" }, `Writes to the ${only}.`), holding);
  }
  const choices = CHOICES.map(({ choice, label }) => h("label", { class: "check" }, h("input", {
    type: "radio", name: "write-target", "data-testid": `target-${choice}`, checked: () => context.targets.chosen.val === choice,
    onchange: () => (context.targets.chosen.val = choice),
  }), label));
  return h("div", { class: "toolbar", style: { marginTop: "6px" } }, h("span", { class: "muted" }, "Write to:"), ...choices, holding);
}
