/**
 * The plots of the Bode page: the Bode figure of the chosen view (closed loop, open loop, plant) and the predicted
 * speed step of the what-if gains beside the drive's; both redraw at once when a slider moves. The time of the last
 * update (prediction, drawing) is shown under the Bode plot.
 */

import { derive, h, type Scope } from "../../lib/dom";
import { sig } from "../../lib/procedures";
import { CURRENT_COLOR, figureInputs, WHATIF_COLOR, type Shown } from "./curves";
import { bodeFigure, stepFigure, type Figure } from "./figure";
import type { BodeModel, BodeViewKind } from "./model";
import { plotView, type PlotHandle } from "./plot";

const VIEWS: [BodeViewKind, string][] = [["closed", "Closed loop"], ["open", "Open loop"], ["plant", "Plant"]];

function shownResults(model: BodeModel): Shown[] {
  const results = model.results.val;
  return model.shown.val.filter((name) => results[name]).map((name) => ({ name, result: results[name] }));
}

export function bodeFigureOf(model: BodeModel): Figure | null {
  const inputs = figureInputs(model.view.val, shownResults(model), model.predicted.val?.prediction ?? null, model.current.val?.prediction ?? null);
  return inputs.curves.length ? bodeFigure(inputs.curves, inputs.lines, inputs.magnitudeTitle) : null;
}

export function stepFigureOf(model: BodeModel): Figure | null {
  const steps = [];
  const current = model.current.val?.prediction.step, predicted = model.predicted.val?.prediction.step;
  if (current) steps.push({ label: "drive's gains", step: current, color: CURRENT_COLOR, dash: "dash" as const });
  if (predicted) steps.push({ label: "what-if gains", step: predicted, color: WHATIF_COLOR });
  return steps.length ? stepFigure(steps) : null;
}

function viewSelect(model: BodeModel): HTMLElement {
  return h("div", { class: "toolbar", role: "tablist" }, VIEWS.map(([key, label]) => h("button", {
    class: () => (model.view.val === key ? "small active" : "small"), "data-testid": `bode-view-${key}`, role: "tab",
    onclick: () => (model.view.val = key),
  }, label)));
}

export function bodePanel(model: BodeModel, scope: Scope): { element: HTMLElement; plot: PlotHandle } {
  const figure = scope.run(() => derive(() => bodeFigureOf(model)));
  const plot = plotView(scope, () => figure.val, "bode-plot", "520px");
  const timing = () => {
    const computed = model.predicted.val?.computeMs;
    return computed === undefined ? "" : `last update: prediction ${sig(computed, "ms")}, drawing ${sig(plot.drawMs.val, "ms")}`;
  };
  const element = h("section", { class: "panel", style: { padding: "4px" } }, viewSelect(model),
    h("div", { class: "empty-state", hidden: () => figure.val !== null, "data-testid": "bode-empty" },
      "Nothing to draw: pick a saved measurement (a plant for the open and closed loops) or measure one."),
    plot.element, h("div", { class: "muted", "data-testid": "bode-timing" }, timing));
  return { element, plot };
}

export function stepPanel(model: BodeModel, scope: Scope): { element: HTMLElement; plot: PlotHandle } {
  const figure = scope.run(() => derive(() => stepFigureOf(model)));
  const plot = plotView(scope, () => figure.val, "bode-step-plot", "260px");
  const element = h("section", { class: "panel" }, h("h2", null, "Predicted speed step"),
    h("div", { class: "panel-body" },
      h("div", { class: "muted", hidden: () => figure.val !== null }, "The step needs a plant measurement with its rigid fit (inertia, friction)."),
      plot.element));
  return { element, plot };
}
