/** Motor catalog: built-in and user motors; choose one for an axis (the drive's motor data then follow it). */

import type { App, Page, PageContext } from "../app";
import { projects, type Motor } from "../client/api";
import { formDialog, toast } from "../components/ui";
import { derive, h, state, type State } from "../lib/dom";

/** How many motor data columns the table shows. */
const DATA_COLUMNS = 4;

export async function motorsPage(context: PageContext): Promise<Page> {
  const { app } = context;
  await app.projectsReady;
  const motors = await projects.motors();
  const filter = state("");
  const selected = state<Motor | null>(motors[0] ?? null);
  const dataKeys = [...new Set(motors.flatMap((motor) => Object.keys(motor.motor_data)))].slice(0, DATA_COLUMNS);
  const shown = derive(() => matching(motors, filter.val));
  const search = h("input", { type: "search", placeholder: "Filter motors", style: { width: "240px" }, "data-testid": "motor-filter",
    oninput: (event: Event) => (filter.val = (event.target as HTMLInputElement).value) });
  return {
    title: "Motor catalog",
    focusSearch: () => { search.focus(); return true; },
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Motor catalog"), h("span", { class: "muted" }, `${motors.length} motors`), search),
      h("div", { class: "grid", style: { gridTemplateColumns: "minmax(0, 1fr) 340px" } },
        h("div", { class: "panel", style: { overflow: "auto" } }, h("table", { class: "data" },
          h("thead", null, h("tr", null, h("th", null, "Reference"), h("th", null, "Description"), dataKeys.map((key) => h("th", { class: "num" }, key)), h("th", null, "Source"))),
          h("tbody", null, () => shown.val.length
            ? shown.val.map((motor) => motorRow(motor, dataKeys, selected))
            : h("tr", null, h("td", { colspan: String(dataKeys.length + 3), class: "muted" }, "No motor matches."))))),
        h("div", { class: "panel" }, h("div", { class: "panel-body" }, () => motorDetail(app, selected.val))))),
  };
}

/** The motors whose reference, description or source contain the filter text (any case). */
export function matching(motors: Motor[], filter: string): Motor[] {
  const text = filter.trim().toLowerCase();
  return motors.filter((motor) => !text || `${motor.reference} ${motor.description} ${motor.source}`.toLowerCase().includes(text));
}

function motorRow(motor: Motor, dataKeys: string[], selected: State<Motor | null>): HTMLElement {
  return h("tr", { "data-testid": `motor-${motor.reference}`, style: { cursor: "pointer" }, onclick: () => (selected.val = motor) },
    h("td", null, motor.reference), h("td", { class: "wrap" }, motor.description),
    dataKeys.map((key) => h("td", { class: "num mono" }, motor.motor_data[key] === undefined ? "" : String(motor.motor_data[key]))),
    h("td", null, motor.builtin ? "built-in" : "user"));
}

function motorDetail(app: App, motor: Motor | null): Node[] | Node {
  if (!motor) return h("span", { class: "muted" }, "The catalog is empty.");
  const pairs = (values: Record<string, number | string>, keyClass: string) =>
    Object.entries(values).map(([key, value]) => h("tr", null, h("td", { class: keyClass }, key), h("td", { class: "mono" }, String(value))));
  return [
    h("h3", { style: { margin: "0 0 4px" } }, motor.reference),
    h("div", { class: "muted" }, motor.description, motor.source ? ` · ${motor.source}` : ""),
    h("table", { class: "kv", style: { marginTop: "8px" } }, h("tbody", null, pairs(motor.motor_data, ""), pairs(motor.objects, "mono"))),
    h("div", { style: { marginTop: "10px" } }, h("button", { class: "primary", onclick: () => useForAxis(app, motor) }, "Use for an axis…")),
  ];
}

/** Apply the motor to a project axis: its motor data and what follows from them in the project. */
function useForAxis(app: App, motor: Motor): void {
  const axes = app.projectsLoaded().flatMap((project) => project.axes.map((axis) => ({ project, axis })));
  const select = h("select", { "data-testid": "motor-axis" },
    axes.map(({ project, axis }, i) => h("option", { value: String(i) }, `${project.name} / ${axis.name} (${axis.device}, node ${axis.node_id})`)));
  formDialog({
    title: `Use motor ${motor.reference}`,
    body: [h("label", { class: "field" }, "Axis", select),
      h("p", { class: "muted", style: { margin: "0" } }, "Sets the axis's motor data (0x6410) and what follows from it in the project: current limits, speed limit, sensor and thermal settings.")],
    confirm: "Use for axis",
    confirmTestid: "motor-apply",
    disabled: axes.length === 0,
    submit: async () => {
      const target = axes[Number(select.value)];
      const choice = await projects.selectMotor(target.project.name, target.axis.name, motor.reference, target.project.revision);
      app.updateProject(choice.project);
      toast(`${motor.reference} set on ${target.axis.name}: ${choice.changed.length} values changed${choice.notes.length ? `, ${choice.notes.length} notes` : ""}`, "ok");
      if (choice.notes.length) toast(choice.notes.join("; "), "info");
    },
  });
}
