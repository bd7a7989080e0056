/**
 * The settings groups of a drive's I/O (analog inputs and output scaling and offset, encoder emulation, the CANopen
 * I/O extension, capture inputs): each value in the dictionary's range, pointers in hex, with the group's live
 * values beside it.
 */

import type { IoGroup, IoSetting } from "../../client/io";
import { h } from "../../lib/dom";
import type { IoPageModel } from "./model";

export function settingsView(model: IoPageModel): HTMLElement {
  return h("div", { class: "grid", style: { gap: "10px" } }, () =>
    (model.config.val?.groups ?? []).map((group) => groupPanel(model, group)));
}

function groupPanel(model: IoPageModel, group: IoGroup): HTMLElement {
  return h("section", { class: "panel", "data-testid": `io-group-${group.key}` },
    h("h2", null, group.title),
    h("div", { class: "panel-body" },
      h("table", { class: "kv" }, h("tbody", null,
        group.settings.map((setting) => settingRow(model, setting)),
        group.live.map((setting) => liveRow(model, setting))))));
}

export function shown(setting: IoSetting, value: number | null | undefined): string {
  if (value === null || value === undefined) return "";
  return setting.pointer ? `0x${value.toString(16).toUpperCase().padStart(8, "0")}` : String(value);
}

function rangeText(setting: IoSetting): string {
  return setting.low !== null && setting.high !== null ? `${setting.low}..${setting.high}` : "";
}

function settingRow(model: IoPageModel, setting: IoSetting): HTMLElement {
  return h("tr", null,
    h("td", { title: setting.address }, setting.label),
    h("td", null, h("input", {
      type: "text",
      size: 12,
      "data-testid": `io-setting-${setting.key}`,
      disabled: !setting.writable,
      value: () => model.settings.val.get(setting.key) ?? shown(setting, setting.value),
      onchange: (event: Event) => model.editSetting(setting.key, (event.target as HTMLInputElement).value),
    })),
    h("td", { class: "muted" }, `${setting.address} ${rangeText(setting)}`));
}

function liveRow(model: IoPageModel, setting: IoSetting): HTMLElement {
  return h("tr", null,
    h("td", { class: "muted" }, setting.label),
    h("td", { "data-testid": `io-live-${setting.key}` }, () => shown(setting, model.live.val?.analog[setting.key] ?? setting.value)),
    h("td", { class: "muted" }, setting.address));
}
