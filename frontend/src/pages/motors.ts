/** Motor catalog: built-in and user motors; choose one for an axis (the drive's motor data then follow it). */

import type { Page, PageContext } from "../app";
import { projects, type Motor } from "../client/api";
import { errorText, openDialog, toast } from "../components/ui";
import { h, replaceChildren } from "../lib/dom";

export async function motorsPage(context: PageContext): Promise<Page> {
  const { app } = context;
  await app.projectsReady;
  const motors = await projects.motors();
  const filter = h("input", { type: "search", placeholder: "Filter motors", style: { width: "240px" }, "data-testid": "motor-filter" });
  const body = h("tbody");
  const detail = h("div", { class: "panel-body" });
  const dataKeys = [...new Set(motors.flatMap((motor) => Object.keys(motor.motor_data)))];

  const choose = (motor: Motor) => {
    const axes = app.projectsLoaded().flatMap((project) => project.axes.map((axis) => ({ project, axis })));
    const dialog = openDialog(`Use motor ${motor.reference}`);
    const select = h("select", { "data-testid": "motor-axis" }, axes.map(({ project, axis }, i) => h("option", { value: String(i) }, `${project.name} / ${axis.name} (${axis.device}, node ${axis.node_id})`)));
    const message = h("div");
    dialog.body.append(h("label", { class: "field" }, "Axis", select),
      h("p", { class: "muted", style: { margin: "0" } }, "Sets the axis's motor data (0x6410) and what follows from it in the project: current limits, speed limit, sensor and thermal settings."), message);
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), h("button", {
      class: "primary", "data-testid": "motor-apply", disabled: axes.length === 0, onclick: async () => {
        const target = axes[Number(select.value)];
        try {
          const choice = await projects.selectMotor(target.project.name, target.axis.name, motor.reference, target.project.revision);
          app.updateProject(choice.project);
          dialog.close();
          toast(`${motor.reference} set on ${target.axis.name}: ${choice.changed.length} values changed${choice.skipped.length ? `, ${choice.skipped.length} skipped` : ""}`, "ok");
          if (choice.skipped.length) toast(choice.skipped.join("; "), "info");
        } catch (error) {
          replaceChildren(message, h("div", { class: "message error" }, errorText(error)));
        }
      },
    }, "Use for axis"));
  };

  const show = (motor: Motor) => {
    replaceChildren(detail,
      h("h3", { style: { margin: "0 0 4px" } }, motor.reference),
      h("div", { class: "muted" }, motor.description, motor.source ? ` · ${motor.source}` : ""),
      h("table", { class: "kv", style: { marginTop: "8px" } }, h("tbody", null,
        Object.entries(motor.motor_data).map(([key, value]) => h("tr", null, h("td", null, key), h("td", { class: "mono" }, String(value)))),
        Object.entries(motor.objects).map(([key, value]) => h("tr", null, h("td", { class: "mono" }, key), h("td", { class: "mono" }, String(value)))))),
      h("div", { style: { marginTop: "10px" } }, h("button", { class: "primary", onclick: () => choose(motor) }, "Use for an axis…")));
  };

  const render = () => {
    const text = filter.value.trim().toLowerCase();
    const shown = motors.filter((motor) => !text || `${motor.reference} ${motor.description} ${motor.source}`.toLowerCase().includes(text));
    replaceChildren(body, shown.length ? shown.map((motor) => h("tr", { "data-testid": `motor-${motor.reference}`, style: { cursor: "pointer" }, onclick: () => show(motor) },
      h("td", null, motor.reference), h("td", { class: "wrap" }, motor.description),
      dataKeys.slice(0, 4).map((key) => h("td", { class: "num mono" }, motor.motor_data[key] === undefined ? "" : String(motor.motor_data[key]))),
      h("td", null, motor.builtin ? "built-in" : "user"))) : h("tr", null, h("td", { colspan: String(dataKeys.slice(0, 4).length + 3), class: "muted" }, "No motor matches.")));
  };
  filter.addEventListener("input", render);
  render();
  if (motors[0]) show(motors[0]);
  else replaceChildren(detail, h("span", { class: "muted" }, "The catalog is empty."));
  return {
    title: "Motor catalog",
    focusSearch: () => { filter.focus(); return true; },
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Motor catalog"), h("span", { class: "muted" }, `${motors.length} motors`), filter),
      h("div", { class: "grid", style: { gridTemplateColumns: "minmax(0, 1fr) 340px" } },
        h("div", { class: "panel", style: { overflow: "auto" } }, h("table", { class: "data" },
          h("thead", null, h("tr", null, h("th", null, "Reference"), h("th", null, "Description"), dataKeys.slice(0, 4).map((key) => h("th", { class: "num" }, key)), h("th", null, "Source"))),
          body)),
        h("div", { class: "panel" }, detail))),
  };
}
