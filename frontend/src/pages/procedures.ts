/**
 * What the procedure views of an axis (Phasing, Current loop, Auto-tuning) share: the page's model (the drive's
 * procedures with their preconditions, the axis's controller, one run per procedure), the controller panel — a
 * procedure that turns the motor needs this page to have armed the axis — and the commissioning order beside it.
 */

import { controllerPanel } from "../components/dashboard/controller";
import { controlAction, createModel, refresh, refreshControl, type ProceduresModel } from "../components/procedures/model";
import { confirmAction } from "../components/ui";
import { h, Scope } from "../lib/dom";
import { buildPath, type AxisView } from "../lib/router";
import type { AxisContext, AxisViewPage } from "./axis";

export interface ProcedureView {
  context: AxisContext;
  model: ProceduresModel;
}

/** Build a procedure view: `main` makes its panels (inside the page's scope) from the shared model. */
export async function procedureView(context: AxisContext, main: (view: ProcedureView) => HTMLElement[]): Promise<AxisViewPage> {
  const { axis, project } = context;
  const scope = new Scope();
  const model = createModel(scope, context.page.app.live, { bus: axis.bus, node: axis.node_id, project: project.name, axis: axis.name });
  const view: ProcedureView = { context, model };
  const element = scope.run(() => h("div", { class: "page" },
    h("div", { class: "grid", style: { gridTemplateColumns: "minmax(0, 1fr) 300px", alignItems: "start" } },
      h("div", { class: "grid", style: { alignContent: "start" } }, main(view)),
      h("div", { class: "grid", style: { alignContent: "start" } }, controller(view), orderPanel(view)))));
  void refresh(model);
  void refreshControl(model);
  return { element, dispose: () => scope.dispose() };
}

/** The axis's Controller panel (also on the Bode page, whose measurement turns the motor). */
export function controller(view: ProcedureView): HTMLElement {
  const { model, context } = view;
  return controllerPanel({
    control: model.holder, askedBy: model.askedBy, busy: model.busy,
    mayTakeOver: () => ["expert", "administrator"].includes(context.page.app.live.user()?.level ?? ""),
    onArm: () => void controlAction(model, "arm"),
    onRelease: () => void controlAction(model, "release"),
    onRequest: () => void controlAction(model, "request"),
    onTakeOver: () => void confirmAction("Take over the axis", "Another client holds this axis. Taking it over makes this page its controller at once (logged).", "Take over", true)
      .then((yes) => (yes ? controlAction(model, "takeOver") : undefined)),
  });
}

const ORDER: [AxisView, string, string][] = [
  ["current-loop", "1. Current loop", "inductance and drive current → 'calc'; current limits and I²t (Fusing while commissioning)"],
  ["phasing", "2. Phasing", "auto-phasing ('apha') after 'calc'; motor phasing ('mcal') at each power-up of an encoder without Hall sensors"],
  ["tuning", "3. Auto-tuning", "identify inertia and friction, compute the gains ('atun'), verify with a step"],
  ["bode", "4. Bode / what-if", "measure the plant and the closed loop, try gains on the measured plant before writing them"],
];

/** The manual's order: auto-phasing on an uncommissioned drive fails before the current loop is calculated. */
function orderPanel(view: ProcedureView): HTMLElement {
  const { project, axis } = view.context;
  return h("section", { class: "panel" }, h("h2", null, "Order (manual §1.8)"),
    h("ol", { class: "panel-body", style: { margin: "0", paddingLeft: "28px" } }, ORDER.map(([target, label, text]) =>
      h("li", null, h("a", { href: buildPath({ page: "axis", project: project.name, axis: axis.name, view: target }), "data-testid": `order-${target}` }, label),
        h("div", { class: "muted" }, text)))));
}
