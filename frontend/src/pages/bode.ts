/**
 * The Bode page of one axis (tab "Bode / what-if", docs/what-if.md): the frequency responses saved under the axis
 * (plant, closed loop) overlaid and compared with their markers, exported as CSV or standalone HTML; the what-if
 * sliders predicting the closed and open loop and the speed step on a measured plant before anything is written;
 * "Write these gains" writes them to the drive and measures the closed loop again to confirm; "Measure" runs a
 * plant or closed-loop measurement (the page must be the axis's armed controller).  plotly.js loads with this page
 * only.
 */

import { createModel, loadLoop, refreshSaved, type BodeModel } from "../components/bode/model";
import { markersTable } from "../components/bode/markers";
import { measurePanel, measureState, remeasure, type MeasureState } from "../components/bode/measure";
import { bodePanel, stepPanel } from "../components/bode/panels";
import { savedPanel } from "../components/bode/saved";
import { whatIfPanel } from "../components/bode/whatif";
import { messageView } from "../components/ui";
import { armed, createModel as createControl, refreshControl, type ProceduresModel } from "../components/procedures/model";
import type { LiveHub } from "../client/live";
import { h, Scope } from "../lib/dom";
import type { AxisContext, AxisViewPage } from "./axis";
import { controller } from "./procedures";

const WRITERS = ["expert", "administrator"];

/** After "Write these gains": measure the closed loop again when this page holds the axis, else say how to. */
async function confirmByMeasuring(model: BodeModel, live: LiveHub, control: ProceduresModel, run: MeasureState, predictedHz: number | null): Promise<void> {
  if (armed(control)) await remeasure(model, live, run, predictedHz);
  else run.check.val = { predictedHz, measuredHz: null, hint: "Arm the axis (Controller panel) and measure the closed loop to confirm." };
}

export function bodeView(context: AxisContext): Promise<AxisViewPage> {
  const { axis, project } = context;
  const scope = new Scope();
  const model = createModel(scope, { bus: axis.bus, node: axis.node_id, project: project.name, axis: axis.name });
  const live = context.page.app.live;
  const control = createControl(scope, live, model.where);
  const run = measureState();
  const expert = () => WRITERS.includes(live.user()?.level ?? "");
  const bode = bodePanel(model, scope);
  const step = stepPanel(model, scope);
  const element = scope.run(() => h("div", { class: "page" },
    messageView(model.message),
    h("div", { class: "grid", style: { gridTemplateColumns: "minmax(0, 1fr) 380px", alignItems: "start" } },
      h("div", { class: "grid", style: { alignContent: "start" } }, bode.element, markersTable(model), step.element),
      h("div", { class: "grid", style: { alignContent: "start" } },
        whatIfPanel(model, { mayWrite: expert, written: (predictedHz) => void confirmByMeasuring(model, live, control, run, predictedHz) }),
        measurePanel(model, live, run, () => armed(control)),
        controller({ context, model: control }),
        savedPanel(model, expert)))));
  void refreshSaved(model);
  void loadLoop(model);
  void refreshControl(control);
  return Promise.resolve({
    element,
    dispose: () => {
      bode.plot.dispose();
      step.plot.dispose();
      scope.dispose();
    },
  });
}
