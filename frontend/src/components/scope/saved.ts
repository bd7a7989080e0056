/**
 * Keeping a capture: export the shown one as CSV, as a standalone HTML file (both made by the server) or as PNG
 * (plotly's toImage of the plot as it is zoomed); save it in the project under the axis; the axis's saved captures,
 * each to re-open or download (a damaged one shows its file and line).
 */

import { savedCaptures, scopeApi, type ExportKind, type SavedCapture } from "../../client/scope";
import { h, state } from "../../lib/dom";
import { download } from "../ui";
import { openSaved, save, type ScopeModel } from "./model";
import { loadPlotly, type PlotHandle } from "./plot";

export function keepView(model: ScopeModel, plot: PlotHandle): HTMLElement {
  const name = state("");
  const nameField: HTMLInputElement = h("input", { "data-testid": "scope-save-name", placeholder: "name (default: time of capture)", style: { width: "220px" }, value: name, oninput: () => (name.val = nameField.value) });
  const none = () => model.capture.val === null;
  return h("section", { class: "panel" },
    h("div", { class: "panel-body grid", style: { gap: "8px" } },
      h("div", { class: "toolbar" },
        h("button", { "data-testid": "scope-export-csv", disabled: none, onclick: () => exportFile(model, "csv") }, "Export CSV"),
        h("button", { "data-testid": "scope-export-html", disabled: none, onclick: () => exportFile(model, "html") }, "Export HTML"),
        h("button", { "data-testid": "scope-export-png", disabled: none, onclick: () => void exportPng(model, plot) }, "Export PNG"),
        h("span", { class: "grow" }),
        nameField,
        h("button", {
          "data-testid": "scope-save", disabled: () => model.captureId.val === null,
          title: "Save the capture in the project under this axis (CSV + JSON)",
          onclick: () => void save(model, name.rawVal).then(() => (name.val = "")),
        }, "Save in project")),
      h("table", { class: "data", "data-testid": "scope-saved" },
        h("thead", null, h("tr", null, ["saved capture", "captured", "channels", "samples", "period", "trigger", ""].map((title) => h("th", null, title)))),
        h("tbody", null, () => model.saved.val.length === 0
          ? h("tr", null, h("td", { colspan: "7", class: "muted" }, "No capture saved under this axis yet."))
          : model.saved.val.map((saved) => savedRow(model, saved))))));
}

function savedRow(model: ScopeModel, saved: SavedCapture): HTMLElement {
  const url = (kind: ExportKind) => savedCaptures.exportUrl(model.project, model.axis, saved.name, kind);
  if (saved.error) return h("tr", null, h("td", { class: "mono" }, saved.name), h("td", { colspan: "6", class: "message error" }, saved.error));
  return h("tr", { "data-testid": "scope-saved-row" },
    h("td", { class: "mono" }, saved.name),
    h("td", null, saved.captured_at),
    h("td", { class: "mono" }, saved.channels.join("  ")),
    h("td", { class: "num" }, String(saved.samples)),
    h("td", { class: "num" }, `${saved.period_ns / 1000} µs`),
    h("td", null, saved.trigger),
    h("td", null, h("span", { class: "toolbar" },
      h("button", { "data-testid": "scope-open-saved", onclick: () => void openSaved(model, saved.name) }, "Open"),
      h("button", { onclick: () => download(url("csv")) }, "CSV"),
      h("button", { onclick: () => download(url("html")) }, "HTML"))));
}

function exportFile(model: ScopeModel, kind: ExportKind): void {
  const capture = model.capture.rawVal, id = model.captureId.rawVal;
  if (!capture) return;
  download(id !== null
    ? scopeApi.exportUrl(model.bus, model.node, id, kind)
    : savedCaptures.exportUrl(model.project, model.axis, capture.name ?? "", kind));
}

async function exportPng(model: ScopeModel, plot: PlotHandle): Promise<void> {
  const graph = plot.graph();
  if (!graph) return;
  const Plotly = await loadPlotly();
  const url = await Plotly.toImage(graph, { format: "png", width: 1400, height: 600 });
  const link = h("a", { href: url, download: `capture node${model.node} ${model.capture.rawVal?.captured_at ?? ""}.png` });
  document.body.append(link);
  link.click();
  link.remove();
}
