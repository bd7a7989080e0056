/**
 * The detail pane of the selected entry: description, drive and project value, the editor (see `write.ts`), bit
 * fields, enumeration, pointer target and the dictionary's facts (the level needed to write it among them). It is built once per selected entry; values
 * that arrive later, and the editor's writability, are bound, so what the user typed stays where it is.
 */

import { bitFields, enumList, pointerTarget, type ValueEditor } from "../editors";
import { derive, h, untrack, type State } from "../../lib/dom";
import { address, isWritable, type Entry, type OdVariable, type Scalar } from "../../lib/od";
import { formatRange, formatValue } from "../../lib/values";
import { entryGroup } from "./rows";
import { writeSection, type WriteContext } from "./write";

export interface DetailContext extends WriteContext {
  selected: State<Entry | null>;
  shown: State<Entry[]>;
  /** Every entry of the dictionary (the pointer picker's choices). */
  entries: Entry[];
}

export function detailPane(context: DetailContext): HTMLElement {
  return h("div", { class: "panel detail", "data-testid": "param-detail" }, () => {
    const entry = context.selected.val;
    if (!entry) {
      return h("div", { class: "empty-state" }, context.shown.val.length ? "Select an entry." : "No entry matches the search.");
    }
    return untrack(() => detailBody(entry, context));
  });
}

function detailBody(entry: Entry, context: DetailContext): HTMLElement {
  const variable = entry.variable;
  const { store } = context;
  const drive = store.driveCell(entry.key);
  const project = store.projectRow(entry.key);
  const canDrive = derive(() => context.hasDrive && store.online.val && isWritable(variable.access));
  const canProject = derive(() => context.hasProject && Boolean(project.val?.editable));
  const shownValue = (): Scalar => drive.val?.raw ?? project.val?.value ?? null;
  const { section: editorSection, editor, holds } = writeSection(entry, context, canDrive, canProject);
  const withEditor = (build: (editor: ValueEditor | null) => HTMLElement) => () => {
    const current = editor.val;
    return untrack(() => build(current));
  };
  return h("div", { class: "panel-body" },
    h("div", { class: "mono muted" }, `${address(entry)}  ·  ${entry.object.name}`),
    h("h3", { "data-testid": "detail-name" }, variable.name),
    variable.description ? h("div", { class: "desc" }, variable.description) : null,
    h("section", null, valuesTable(entry, context, () => (editor.val ? holds.val : null))),
    editorSection,
    variable.bits.length ? withEditor((current) => bitFields(variable, shownValue, current)) : null,
    Object.keys(variable.enum).length ? enumList(variable, shownValue) : null,
    variable.is_pointer ? withEditor((current) => pointerTarget(shownValue, context.entries, current)) : null,
    h("section", null, facts(entry)),
  );
}

function kv(label: Node | string | (() => Node | string), value: Node | string | (() => Node | string)): HTMLElement {
  return h("tr", null, h("td", null, label), h("td", null, value));
}

/** Drive and project value side by side; the one the editor's field holds is marked. */
function valuesTable(entry: Entry, context: DetailContext, holds: () => "drive" | "project" | null): HTMLElement {
  const variable = entry.variable;
  const drive = context.store.driveCell(entry.key);
  const project = context.store.projectRow(entry.key);
  const withUnit = (raw: Scalar) => `${formatValue(variable, raw)} ${variable.unit}`.trim();
  const driveValue = () => {
    const cell = drive.val;
    if (cell?.error) return h("span", { class: "error-text" }, cell.error);
    if (cell) return h("span", { class: "mono", "data-testid": "detail-drive-value" }, withUnit(cell.raw) + rawSuffix(entry, cell.raw));
    return context.store.online.val ? "reading…" : "drive offline";
  };
  const projectValue = () => {
    const row = project.val;
    if (!row) return "—";
    if (row.value === null) return h("span", { class: "mono", "data-testid": "detail-project-value" }, h("span", { class: "muted" }, "not set, no default"));
    return h("span", { class: "mono", "data-testid": "detail-project-value" }, withUnit(row.value),
      h("span", { class: "muted" }, row.file ? ` (${row.file})` : " (default)"));
  };
  const label = (side: "drive" | "project", text: string) => () =>
    h("span", { "data-testid": `detail-${side}-label` }, text, holds() === side ? h("span", { class: "muted" }, " ◂ field") : null);
  return h("table", { class: "kv" }, h("tbody", null,
    context.hasDrive ? kv(label("drive", "Drive"), driveValue) : null,
    context.hasProject ? kv(label("project", "Project"), projectValue) : null));
}

function facts(entry: Entry): HTMLElement {
  const variable = entry.variable;
  return h("table", { class: "kv" }, h("tbody", null,
    kv("Type", `${variable.data_type}, ${variable.access}${variable.pdo_mappable ? ", PDO mappable" : ""}`),
    kv("Range", formatRange(variable) || "—"),
    kv("Default", variable.default === null ? "none" : `${formatValue(variable, variable.default)} ${variable.unit}`.trim()),
    variable.scale !== 1 || variable.offset !== 0
      ? kv("Scaling", `physical = raw × ${variable.scale}${variable.offset ? ` + ${variable.offset}` : ""}`) : null,
    kv("Write level", h("span", { "data-testid": "detail-write-level", title: "the lowest user level that may write it to a drive (docs/security.md)" },
      writeLevelText(variable.write_level))),
    kv("Saved in", variable.save_type === "NONE" ? "not saved" : `${variable.save_type}.TXT`),
    kv("Group", entryGroup(entry) || "—"),
    variable.reference ? kv("Manual", variable.reference) : null,
  ));
}

/** The user level needed to write the entry, as the server's dictionary says (null: nobody writes it). */
export function writeLevelText(level: OdVariable["write_level"]): string {
  if (level === null) return "read-only";
  return `${level.charAt(0).toUpperCase()}${level.slice(1)} or higher`;
}

function rawSuffix(entry: Entry, raw: Scalar): string {
  if (typeof raw !== "number") return "";
  const { scale, offset } = entry.variable;
  return scale !== 1 || offset !== 0 ? `  (raw ${raw})` : "";
}
