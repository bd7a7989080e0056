/**
 * The parameter table: a header and the virtualised rows (only those in view exist). Each row binds its cells to
 * the store, so a value read or written shows at once; the rows of one render pass share a scope, disposed when
 * the list renders the next pass (their elements are gone then).
 */

import { Scope, effect, h, untrack, type State } from "../../lib/dom";
import { formatHex } from "../../lib/numbers";
import { address, isVar, isWritable, shortType, type Entry } from "../../lib/od";
import { formatValue } from "../../lib/values";
import { VirtualList } from "../vlist";
import type { Row } from "./rows";
import type { ParameterStore } from "./store";

const ROW_HEIGHT = 24;

export interface TableProps {
  store: ParameterStore;
  rows: State<Row[]>;
  selected: State<Entry | null>;
  /** Whether there is a drive (else the Value column shows the default) and a project. */
  hasDrive: boolean;
  hasProject: boolean;
  /** Rows came into view (their drive values are read). */
  onVisible(rows: Row[]): void;
  /** A row was clicked: its entry's key. */
  onSelect(key: string): void;
  /** A key in the table (selection, Enter), a double click (edit). */
  onKey(event: KeyboardEvent): void;
  onOpen(): void;
}

export class ParameterTable {
  readonly element: HTMLElement;
  readonly list: VirtualList<Row>;
  /** The rows in view (read again when the drive comes online). */
  visible: Row[] = [];
  private pass = new Scope();
  private previousPass = new Scope();

  constructor(private readonly props: TableProps) {
    this.list = new VirtualList<Row>(ROW_HEIGHT, (row) => this.pass.run(() => renderRow(row, props)));
    this.list.onVisible = (rows) => {
      this.previousPass.dispose();
      this.previousPass = this.pass;
      this.pass = new Scope();
      this.visible = rows;
      props.onVisible(rows);
    };
    const scroller = this.list.element;
    scroller.addEventListener("keydown", (event) => props.onKey(event));
    scroller.addEventListener("click", (event) => {
      const row = (event.target as Element).closest<HTMLElement>(".prow.entry");
      if (row?.dataset.key) props.onSelect(row.dataset.key);
    });
    scroller.addEventListener("dblclick", () => props.onOpen());
    const header = h("div", { class: "prow head" },
      h("span", null, "Index"), h("span", null, "Name"),
      h("span", { class: "num" }, props.hasDrive ? "Drive" : "Value"), h("span", null, "Unit"),
      h("span", { class: "num" }, props.hasProject ? "Project" : ""), h("span", { class: "num" }, "Default"),
      h("span", null, "Type"));
    this.element = h("div", { class: "panel ptable", "data-testid": "param-table" }, header, scroller);
  }

  /** Show the rows (and again whenever they change: a new filter starts at the top). Returns the stop. */
  follow(): () => void {
    return effect(() => {
      const rows = this.props.rows.val;
      untrack(() => {
        this.list.setItems(rows);
        this.list.element.scrollTop = 0;
      });
    });
  }

  scrollTo(entry: Entry): void {
    for (let position = 0; position < this.list.count(); position++) {
      const row = this.list.itemAt(position);
      if (row?.kind === "entry" && row.entry === entry) {
        this.list.scrollToPosition(position);
        return;
      }
    }
  }

  focus(): void {
    this.list.element.focus();
  }

  dispose(): void {
    this.pass.dispose();
    this.previousPass.dispose();
  }
}

function renderRow(row: Row, props: TableProps): HTMLElement {
  if (row.kind === "group") {
    return h("div", { class: "prow group" }, h("span", null, row.name), h("span", { class: "count" }, `${row.count}`));
  }
  if (row.kind === "object") {
    return h("div", { class: "prow object" }, h("span", { class: "mono" }, formatHex(row.object.index)),
      h("span", null, row.object.name), h("span", { class: "muted" }, row.object.kind));
  }
  return entryRow(row.entry, row.sub, props);
}

function entryRow(entry: Entry, sub: boolean, props: TableProps): HTMLElement {
  const { store, selected } = props;
  const variable = entry.variable;
  const project = store.projectRow(entry.key);
  const writable = isWritable(variable.access);
  const name: (Node | string)[] = sub || isVar(entry.object) || variable.name === entry.object.name
    ? [variable.name]
    : [variable.name, h("span", { class: "muted" }, ` · ${entry.object.name}`)];
  return h("div", {
    class: () => `prow entry ${sub ? "sub" : ""} ${selected.val === entry ? "selected" : ""}`,
    "data-key": entry.key, "data-address": address(entry), title: variable.description || variable.name,
  },
  h("span", { class: "mono" }, address(entry)),
  h("span", { class: `name ${writable ? "" : "ro"}` }, ...name),
  h("span", { class: "num mono", "data-col": "drive" }, () => driveText(entry, props)),
  h("span", { class: "muted" }, variable.unit),
  h("span", { class: () => `num mono ${project.val?.file ? "" : "stale"}`, "data-col": "project" },
    () => (project.val ? formatValue(variable, project.val.value) : "")),
  h("span", { class: "num mono stale" }, formatValue(variable, variable.default)),
  h("span", { class: "muted", title: `${variable.data_type}, ${variable.access}` }, `${shortType(variable.data_type)}${writable ? "" : " " + variable.access}`),
  );
}

/** The drive cell: the value (amber when it differs from the project's), a read error, or the default. */
function driveText(entry: Entry, props: TableProps): Node | string {
  const variable = entry.variable;
  const cell = props.store.driveCell(entry.key).val;
  if (cell?.error) return h("span", { class: "cell-error", title: cell.error }, "read error");
  if (cell) {
    const differs = props.store.differs(entry);
    const project = props.store.projectRow(entry.key).val;
    return h("span", {
      class: differs ? "differs" : "",
      title: differs ? `differs from the project value ${formatValue(variable, project?.value)}` : "",
    }, formatValue(variable, cell.raw));
  }
  if (!props.hasDrive) return h("span", { class: "stale" }, formatValue(variable, variable.default));
  return "";
}
