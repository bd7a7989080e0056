/** Commissioning checklist of one axis in the manual's order; each step links to the page or group that does it. */

import { projects, type Template } from "../client/api";
import { errorText, openDialog, toast } from "../components/ui";
import { STEPS, stepKeys, stepStatus, type Step } from "../lib/commissioning";
import { h, replaceChildren } from "../lib/dom";
import { formatHex } from "../lib/numbers";
import { buildPath } from "../lib/router";
import type { AxisContext, AxisViewPage } from "./axis";

const TICKS_KEY = "servostudio.commissioning";

type Ticks = Record<string, string>;

export async function commissioningView(context: AxisContext): Promise<AxisViewPage> {
  const { project, dictionary, page } = context;
  let axis = context.axis;
  const list = h("ol", { class: "steps", "data-testid": "checklist" });
  const summary = h("span", { class: "muted", "data-testid": "checklist-summary" });
  const tickKey = `${project.name}/${axis.name}`;
  const ticks = (): Ticks => (JSON.parse(localStorage.getItem(TICKS_KEY) ?? "{}") as Record<string, Ticks>)[tickKey] ?? {};
  const setTick = (step: string, on: boolean) => {
    const all = JSON.parse(localStorage.getItem(TICKS_KEY) ?? "{}") as Record<string, Ticks>;
    const mine = all[tickKey] ?? {};
    if (on) mine[step] = new Date().toISOString();
    else delete mine[step];
    all[tickKey] = mine;
    localStorage.setItem(TICKS_KEY, JSON.stringify(all));
  };

  const templateDialog = async () => {
    const templates: Template[] = await projects.templates(axis.device);
    const dialog = openDialog("Drive configuration: application template");
    const select = h("select", { "data-testid": "template-select" }, templates.map((t) => h("option", { value: t.key }, t.title)));
    if (axis.application) select.value = axis.application;
    const text = h("div", { class: "muted" });
    const message = h("div");
    const describe = () => {
      const chosen = templates.find((t) => t.key === select.value);
      replaceChildren(text, chosen ? [chosen.description, chosen.settings.length ? h("ul", null, chosen.settings.map((s) =>
        h("li", null, `${formatHex(s.index)}.${s.subindex} = ${s.value}: ${s.why}`))) : ""] : "");
    };
    select.addEventListener("change", describe);
    describe();
    dialog.body.append(templates.length ? h("label", { class: "field" }, "Template", select) : h("div", { class: "message warn" }, `No template is defined for ${dictionary.product_name}.`), text, message);
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), h("button", {
      class: "primary", disabled: templates.length === 0, "data-testid": "template-apply", onclick: async () => {
        try {
          const fresh = await projects.get(project.name);
          const choice = await projects.applyApplication(project.name, axis.name, select.value, fresh.revision);
          page.app.updateProject(choice.project);
          axis = choice.project.axes.find((a) => a.name === axis.name) ?? axis;
          dialog.close();
          toast(`Template applied: ${choice.changed.length} values set in the project`, "ok");
          await render();
        } catch (error) {
          replaceChildren(message, h("div", { class: "message error" }, errorText(error)));
        }
      },
    }, "Apply to project"));
  };

  const link = (step: Step): Node => {
    const view = (target: "dashboard" | "backup" | "parameters", label: string, query: Record<string, string> = {}) =>
      h("a", { class: "button", href: buildPath({ page: "axis", project: project.name, axis: axis.name, view: target }, query) }, label);
    const firstObject = step.objects.map((o) => dictionary.objects.find((d) => d.index === o.index)).find(Boolean);
    const parameters = firstObject ? view("parameters", "Parameters", { group: firstObject.group }) : null;
    switch (step.page) {
      case "template":
        return h("span", { class: "toolbar" }, h("button", { "data-testid": "open-template", onclick: () => void templateDialog() }, "Choose template…"));
      case "motors":
        return h("span", { class: "toolbar" }, h("a", { class: "button", href: "/motors" }, "Motor catalog"), parameters);
      case "dashboard":
        return h("span", { class: "toolbar" }, view("dashboard", "Dashboard"), parameters);
      case "backup":
        return h("span", { class: "toolbar" }, view("backup", "Backup / store"));
      default:
        return parameters ?? h("span", { class: "muted" }, "—");
    }
  };

  const render = async () => {
    let explicit = new Set<string>();
    try {
      const rows = (await projects.parameters(project.name, axis.name)).parameters;
      explicit = new Set(rows.filter((row) => row.file !== null).map((row) => `${row.index}.${row.subindex}`));
    } catch (error) {
      replaceChildren(list, h("li", null, h("span", { class: "error-text" }, errorText(error))));
      return;
    }
    const ticked = ticks();
    let done = 0;
    let applicable = 0;
    replaceChildren(list, STEPS.map((step, position) => {
      const keys = stepKeys(step, dictionary);
      const extra = step.key === "config" ? Boolean(axis.application) : step.key === "motor" ? Boolean(axis.motor) : false;
      const status = stepStatus(step, keys, explicit, Boolean(ticked[step.key]), extra);
      if (status.state !== "not-applicable") applicable++;
      if (status.state === "done") done++;
      const detail = step.key === "config" && axis.application ? `template "${axis.application}"`
        : step.key === "motor" && axis.motor ? `motor ${axis.motor}${status.total ? ` · ${status.set} of ${status.total} values set` : ""}`
          : status.state === "not-applicable" ? `not in the ${dictionary.product_name} dictionary`
            : status.total ? `${status.set} of ${status.total} values set in the project` : "";
      const tickBox = step.manual ? h("label", { class: "check", title: "Tick when done (remembered in this browser)" },
        h("input", { type: "checkbox", checked: Boolean(ticked[step.key]), "data-testid": `tick-${step.key}`, onchange: (event: Event) => { setTick(step.key, (event.target as HTMLInputElement).checked); void render(); } }),
        ticked[step.key] ? `done ${ticked[step.key].slice(0, 16).replace("T", " ")}` : "done") : null;
      return h("li", { class: status.state, "data-testid": `step-${step.key}`, "data-state": status.state },
        h("span", { class: "mark" }, status.state === "done" ? "✓" : String(position + 1)),
        h("div", null, h("strong", null, step.title), h("div", { class: "checks" }, detail)),
        h("div", { class: "muted" }, step.summary, tickBox ? [" ", tickBox] : null),
        link(step));
    }));
    summary.textContent = `${done} of ${applicable} steps done`;
  };
  await render();
  return {
    element: h("div", { class: "page" },
      h("div", { class: "toolbar" }, h("strong", null, "Commissioning order (manual §1.8)"), summary),
      h("div", { class: "panel" }, list)),
  };
}
