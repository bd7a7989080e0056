/**
 * The frequency responses saved under the axis, newest first: overlay any of them (compare), pick the plant the
 * what-if runs on, download one as CSV (the pinned columns) or standalone HTML, the overlay as one HTML file, and
 * delete (Expert, confirmed).
 */

import { savedFrequency, type SavedSummary } from "../../client/frequency";
import { h, type Child } from "../../lib/dom";
import { sig } from "../../lib/procedures";
import { confirmAction } from "../ui";
import { removeSaved, toggleShown, usePlant, type BodeModel } from "./model";

const LOOPS: Record<string, string> = { plant: "plant", closed: "closed loop" };

function summaryText(item: SavedSummary): string {
  if (item.error) return item.error;
  const markers = item.markers;
  const found = item.loop === "closed" ? `bandwidth ${sig(markers?.bandwidth_hz, "Hz")}`
    : `resonance ${sig(markers?.resonance_hz, "Hz")}, anti-resonance ${sig(markers?.antiresonance_hz, "Hz")}`;
  return `${LOOPS[item.loop ?? ""] ?? item.loop ?? "?"} · ${(item.time ?? "").replace("T", " ").replace("Z", "")} · ${found}${item.aborted ? ` · aborted: ${item.aborted}` : ""}`;
}

function row(model: BodeModel, item: SavedSummary, mayDelete: () => boolean): HTMLElement {
  const { project, axis } = model.where;
  const url = (kind: "csv" | "html") => savedFrequency.exportUrl(project, axis, item.name, kind);
  const plantChoice = item.loop === "plant" && !item.error
    ? h("label", { class: "check", title: "Run the what-if on this plant measurement" },
      h("input", { type: "radio", name: "whatif-plant", "data-testid": "saved-plant", checked: () => model.plantName.val === item.name,
        onchange: () => void usePlant(model, item.name) }), " what-if")
    : null;
  return h("div", { class: "saved-item", "data-testid": "bode-saved-row", "data-name": item.name, style: { padding: "4px 0", borderBottom: "1px solid var(--border)" } },
    h("label", { class: "check" },
      h("input", { type: "checkbox", "data-testid": "saved-show", disabled: Boolean(item.error), checked: () => model.shown.val.includes(item.name),
        onchange: (event: Event) => void toggleShown(model, item.name, (event.target as HTMLInputElement).checked) }),
      h("strong", null, ` ${item.name}`)),
    h("div", { class: "muted wrap" }, summaryText(item)),
    h("div", { class: "toolbar" }, plantChoice,
      h("a", { class: "button small", href: url("csv"), download: "", "data-testid": "saved-csv" }, "CSV"),
      h("a", { class: "button small", href: url("html"), download: "", "data-testid": "saved-html" }, "HTML"),
      h("button", { class: "small danger", "data-testid": "saved-delete", disabled: () => !mayDelete(),
        title: () => (mayDelete() ? "Delete this saved result" : "Deleting project records needs the Expert level"),
        onclick: () => void confirmAction("Delete saved result", `Delete "${item.name}" from axis ${axis}?`, "Delete", true)
          .then((yes) => (yes ? removeSaved(model, item.name) : undefined)) }, "Delete")));
}

/** One HTML file of everything overlaid (the first shown is the reference). */
function overlayLink(model: BodeModel): Child {
  const shown = model.shown.val;
  if (shown.length < 2) return null;
  const href = savedFrequency.exportUrl(model.where.project, model.where.axis, shown[0], "html", shown.slice(1));
  return h("a", { class: "button small", href, download: "", "data-testid": "overlay-html" }, `Overlay of ${shown.length} as HTML`);
}

export function savedPanel(model: BodeModel, mayDelete: () => boolean): HTMLElement {
  const list = (): Child => {
    if (model.savedError.val) return h("div", { class: "error-text" }, model.savedError.val);
    const saved = model.saved.val;
    if (saved === null) return h("div", { class: "muted" }, "Reading…");
    if (saved.length === 0) return h("div", { class: "muted", "data-testid": "bode-saved-none" }, `No frequency response saved for axis ${model.where.axis} yet.`);
    return saved.map((item) => row(model, item, mayDelete));
  };
  return h("section", { class: "panel" }, h("h2", null, "Saved measurements"),
    h("div", { class: "panel-body", "data-testid": "bode-saved" }, list, h("div", { class: "toolbar" }, () => overlayLink(model))));
}
