/**
 * The oscilloscope of one axis (tab "Scope"): the drive's recorder configured, armed, forced and stopped from the
 * page (keys a, f, s), the capture drawn with plotly.js (loaded on first use) with cursors, measurements, a math
 * trace and an FFT view, exported (CSV, HTML, PNG) and saved in the project under the axis; below, live roll mode
 * (the same channels streamed through TPDOs, `components/scope/roll.ts`).
 */

import { serverBus } from "../client/drives";
import { scopeApi } from "../client/scope";
import { controlsView } from "../components/scope/controls";
import { arm, createModel, force, refreshSaved, stop } from "../components/scope/model";
import { recordableIndex } from "../components/scope/picker";
import { plotView } from "../components/scope/plot";
import { readoutView } from "../components/scope/readout";
import { rollView } from "../components/scope/roll";
import { keepView } from "../components/scope/saved";
import { errorText } from "../components/ui";
import { h, Scope } from "../lib/dom";
import type { AxisContext, AxisViewPage } from "./axis";

const SHORTCUTS: Record<string, (model: ReturnType<typeof createModel>) => Promise<void>> = {
  "scope-arm": arm,
  "scope-force": force,
  "scope-stop": stop,
};

export async function scopeView(context: AxisContext): Promise<AxisViewPage> {
  const { axis, project, dictionary } = context;
  const model = createModel(context.page.app.live, dictionary, { bus: axis.bus, node: axis.node_id, project: project.name, axis: axis.name });
  const index = recordableIndex(dictionary);
  const scope = new Scope();
  const plot = plotView(model, scope);
  const roll = rollView(model, scope);
  const element = scope.run(() => h("div", { class: "page grid", style: { gap: "10px", alignContent: "start" } },
    controlsView(model, index), plot.element, readoutView(model), keepView(model, plot), roll.element));
  void load(model);
  return {
    element,
    shortcut: (action) => {
      const run = SHORTCUTS[action];
      if (run) void run(model);
      return run !== undefined;
    },
    dispose: () => {
      plot.dispose();
      roll.dispose();
      scope.dispose();
    },
  };
}

/** The recorder's description (a drive without one says why) and the axis's saved captures. */
async function load(model: ReturnType<typeof createModel>): Promise<void> {
  try {
    model.info.val = await scopeApi.info(model.bus, model.node);
    model.stage.val = model.info.rawVal?.status ?? "idle";
  } catch (error) {
    model.message.val = { text: `${model.axis} (node ${model.node} on ${serverBus(model.bus)}): ${errorText(error)}`, tone: "error", testid: "scope-unavailable" };
  }
  await refreshSaved(model);
}
