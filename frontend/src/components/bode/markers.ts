/**
 * The markers side by side: each overlaid measurement (its saved markers) and the two predictions (the drive's
 * gains, the what-if gains) — the comparison of result sets in numbers.
 */

import type { Markers } from "../../lib/whatif/markers";
import { h } from "../../lib/dom";
import { sig } from "../../lib/procedures";
import type { BodeModel } from "./model";

export const MARKER_ROWS: [keyof Markers, string, string][] = [
  ["bandwidth_hz", "bandwidth (−3 dB)", "Hz"],
  ["phase_margin_deg", "phase margin", "°"],
  ["gain_margin_db", "gain margin", "dB"],
  ["resonance_hz", "resonance", "Hz"],
  ["antiresonance_hz", "anti-resonance", "Hz"],
];

export interface MarkerColumn {
  title: string;
  markers: Partial<Markers> | null | undefined;
}

export function markerColumns(model: BodeModel): MarkerColumn[] {
  const shown = model.shown.val.map((name) => ({ title: name, markers: model.results.val[name]?.markers as Partial<Markers> | undefined }));
  const predicted = [
    { title: "predicted, drive's gains", markers: model.current.val?.prediction.markers },
    { title: "predicted, what-if", markers: model.predicted.val?.prediction.markers },
  ].filter((column) => column.markers);
  return [...shown, ...predicted];
}

export function markersTable(model: BodeModel): HTMLElement {
  return h("section", { class: "panel" }, h("h2", null, "Markers"),
    h("div", { class: "panel-body", style: { overflowX: "auto" } }, () => {
      const columns = markerColumns(model);
      if (columns.length === 0) return h("div", { class: "muted" }, "Nothing shown yet.");
      return h("table", { class: "data", "data-testid": "bode-markers" },
        h("thead", null, h("tr", null, h("th", null, ""), columns.map((column) => h("th", null, column.title)))),
        h("tbody", null, MARKER_ROWS.map(([key, label, unit]) => h("tr", { "data-testid": `marker-${key}` }, h("td", null, label),
          columns.map((column) => h("td", { class: "num" }, sig(column.markers?.[key] ?? null, unit)))))));
    }));
}
