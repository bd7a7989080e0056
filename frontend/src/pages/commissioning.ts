/** Commissioning checklist of one axis in the manual's order; each step links to the page or group that does it. */

import { projects, type AxisConfig, type Template } from "../client/api";
import { errorText, formDialog, toast } from "../components/ui";
import { loader, type Loaded } from "../lib/async";
import { STEPS, stepKeys, stepStatus, type Step, type StepStatus } from "../lib/commissioning";
import { h, Scope, state, type State } from "../lib/dom";
import { formatHex } from "../lib/numbers";
import { buildPath, type AxisView } from "../lib/router";
import { axisTabs } from "../lib/axis-tabs";
import type { AxisContext, AxisViewPage } from "./axis";

const TICKS_KEY = "servostudio.commissioning";

/** The procedure pages a step links to (the current loop page also has the I²t protection). */
const PROCEDURE_PAGES = { "current-loop": "Current loop", phasing: "Phasing", tuning: "Auto-tuning" };

/** Step key → when the user ticked it (ISO time). */
type Ticks = Record<string, string>;

interface ChecklistView {
  context: AxisContext;
  axis: State<AxisConfig>;
  /** The entries the project files set (`index.sub`), loaded again when the axis changes. */
  explicit: State<Loaded<Set<string>>>;
  ticks: State<Ticks>;
}

export async function commissioningView(context: AxisContext): Promise<AxisViewPage> {
  const scope = new Scope();
  const axis = state(context.axis);
  const tickKey = `${context.project.name}/${context.axis.name}`;
  const ticks = state(readTicks()[tickKey] ?? {});
  scope.effect(() => saveTicks(tickKey, ticks.val));
  const explicit = loader(scope, () => axis.val, async (current) => {
    const rows = (await projects.parameters(context.project.name, current.name)).parameters;
    return new Set(rows.filter((row) => row.file !== null).map((row) => `${row.index}.${row.subindex}`));
  });
  const view: ChecklistView = { context, axis, explicit, ticks };
  return {
    dispose: () => scope.dispose(),
    element: scope.run(() => h("div", { class: "page" },
      h("div", { class: "toolbar" }, h("strong", null, "Commissioning order (manual §1.8)"),
        h("span", { class: "muted", "data-testid": "checklist-summary" }, () => summary(view))),
      h("div", { class: "panel" }, h("ol", { class: "steps", "data-testid": "checklist" }, () => checklist(view))))),
  };
}

function readTicks(): Record<string, Ticks> {
  return JSON.parse(localStorage.getItem(TICKS_KEY) ?? "{}") as Record<string, Ticks>;
}

function saveTicks(tickKey: string, ticks: Ticks): void {
  localStorage.setItem(TICKS_KEY, JSON.stringify({ ...readTicks(), [tickKey]: ticks }));
}

/** Each step's status from the project files, the axis's template and motor, and the user's ticks. */
function statuses(view: ChecklistView, explicit: Set<string>): StepStatus[] {
  const axis = view.axis.val;
  const ticks = view.ticks.val;
  return STEPS.map((step) => {
    const extra = step.key === "config" ? Boolean(axis.application) : step.key === "motor" ? Boolean(axis.motor) : false;
    return stepStatus(step, stepKeys(step, view.context.dictionary), explicit, Boolean(ticks[step.key]), extra);
  });
}

function summary(view: ChecklistView): string {
  const loaded = view.explicit.val;
  if (loaded.status !== "ready") return "";
  const all = statuses(view, loaded.value);
  return `${all.filter((s) => s.state === "done").length} of ${all.filter((s) => s.state !== "not-applicable").length} steps done`;
}

function checklist(view: ChecklistView): Node[] | Node | null {
  const loaded = view.explicit.val;
  if (loaded.status === "loading") return null;
  if (loaded.status === "failed") return h("li", null, h("span", { class: "error-text" }, errorText(loaded.error)));
  const all = statuses(view, loaded.value);
  return STEPS.map((step, position) => stepItem(view, step, position, all[position]));
}

function stepDetail(view: ChecklistView, step: Step, status: StepStatus): string {
  const axis = view.axis.val;
  if (step.key === "config" && axis.application) return `template "${axis.application}"`;
  if (step.key === "motor" && axis.motor) return `motor ${axis.motor}${status.total ? ` · ${status.set} of ${status.total} values set` : ""}`;
  if (status.state === "not-applicable") return `not in the ${view.context.dictionary.product_name} dictionary`;
  return status.total ? `${status.set} of ${status.total} values set in the project` : "";
}

function stepItem(view: ChecklistView, step: Step, position: number, status: StepStatus): HTMLElement {
  const ticked = view.ticks.val[step.key];
  const tick = (on: boolean) => {
    const next = { ...view.ticks.rawVal };
    if (on) next[step.key] = new Date().toISOString();
    else delete next[step.key];
    view.ticks.val = next;
  };
  const tickBox = step.manual ? h("label", { class: "check", title: "Tick when done (remembered in this browser)" },
    h("input", { type: "checkbox", checked: Boolean(ticked), "data-testid": `tick-${step.key}`, onchange: (event: Event) => tick((event.target as HTMLInputElement).checked) }),
    ticked ? `done ${ticked.slice(0, 16).replace("T", " ")}` : "done") : null;
  return h("li", { class: status.state, "data-testid": `step-${step.key}`, "data-state": status.state },
    h("span", { class: "mark" }, status.state === "done" ? "✓" : String(position + 1)),
    h("div", null, h("strong", null, step.title), h("div", { class: "checks" }, stepDetail(view, step, status))),
    h("div", { class: "muted" }, step.summary, tickBox ? [" ", tickBox] : null),
    stepLink(view, step));
}

/** Where the step is done: the template dialog, the motor catalog, the dashboard, backup, or its parameter group. */
function stepLink(view: ChecklistView, step: Step): Node {
  const { project, dictionary } = view.context;
  const axis = view.axis.val;
  const offered = new Set(axisTabs(dictionary).map((tab) => tab.view)); // no link to a tab the device has not
  const page = (target: AxisView, label: string, query: Record<string, string> = {}) => !offered.has(target) ? null
    : h("a", { class: "button", href: buildPath({ page: "axis", project: project.name, axis: axis.name, view: target }, query) }, label);
  const firstObject = step.objects.map((o) => dictionary.objects.find((d) => d.index === o.index)).find(Boolean);
  const parameters = firstObject ? page("parameters", "Parameters", { group: firstObject.group }) : null;
  switch (step.page) {
    case "template":
      return h("span", { class: "toolbar" }, h("button", { "data-testid": "open-template", onclick: () => void templateDialog(view) }, "Choose template…"));
    case "motors":
      return h("span", { class: "toolbar" }, h("a", { class: "button", href: "/motors" }, "Motor catalog"), parameters);
    case "dashboard":
      return h("span", { class: "toolbar" }, page("dashboard", "Dashboard"), parameters);
    case "backup":
      return h("span", { class: "toolbar" }, page("backup", "Backup / store"));
    case "current-loop":
    case "phasing":
    case "tuning":
      return h("span", { class: "toolbar" }, page(step.page, PROCEDURE_PAGES[step.page]),
        step.page === "tuning" ? page("bode", "Bode / what-if") : null, parameters);
    default:
      return parameters ?? h("span", { class: "muted" }, "—");
  }
}

/** Choose the axis's application template (the settings each makes are listed) and apply it to the project. */
async function templateDialog(view: ChecklistView): Promise<void> {
  const { project, dictionary, page } = view.context;
  const axis = view.axis.rawVal;
  const templates: Template[] = await projects.templates(axis.device);
  const chosen = state("");
  const select = h("select", { "data-testid": "template-select", onchange: () => (chosen.val = select.value) },
    templates.map((t) => h("option", { value: t.key }, t.title)));
  if (axis.application) select.value = axis.application;
  chosen.val = select.value;
  const text = h("div", { class: "muted" }, () => templateText(templates.find((t) => t.key === chosen.val)));
  formDialog({
    title: "Drive configuration: application template",
    body: [templates.length ? h("label", { class: "field" }, "Template", select) : h("div", { class: "message warn" }, `No template is defined for ${dictionary.product_name}.`), text],
    confirm: "Apply to project",
    confirmTestid: "template-apply",
    disabled: templates.length === 0,
    submit: async () => {
      const fresh = await projects.get(project.name);
      const choice = await projects.applyApplication(project.name, axis.name, select.value, fresh.revision);
      page.app.updateProject(choice.project);
      view.axis.val = choice.project.axes.find((a) => a.name === axis.name) ?? axis;
      toast(`Template applied: ${choice.changed.length} values set in the project`, "ok");
    },
  });
}

function templateText(template: Template | undefined): (Node | string)[] {
  if (!template) return [];
  return [template.description, template.settings.length ? h("ul", null, template.settings.map((s) =>
    h("li", null, `${formatHex(s.index)}.${s.subindex} = ${s.value}: ${s.why}`))) : ""];
}
