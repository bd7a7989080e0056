/**
 * The inputs and outputs tables: each line with its function (a picker of what the device allows), its polarity
 * where the device has one, and its live level. An edit shows at once and is written with the others.
 */

import type { IoConfig, IoFunction, IoInput, IoOutput } from "../../client/io";
import { h } from "../../lib/dom";
import type { IoPageModel, LineEdit } from "./model";

type Which = "inputs" | "outputs";
type Line = IoInput | IoOutput;

export function linesTable(model: IoPageModel, which: Which): HTMLElement {
  return h("div", null, () => {
    const config = model.config.val;
    if (!config) return null;
    const lines: Line[] = config[which];
    if (!lines.length) return h("p", { class: "muted", "data-testid": `io-${which}-none` }, `No configurable ${which}.`);
    const polarity = lines.some((line) => line.inverted !== null);
    return h("table", { class: "grid-table", "data-testid": `io-table-${which}` },
      h("thead", null, h("tr", null, h("th", null, which === "inputs" ? "Input" : "Output"), h("th", null, "Function"),
        polarity ? h("th", null, "Inverted") : null, h("th", null, "Live"))),
      h("tbody", null, lines.map((line) => lineRow(model, config, which, line, polarity))));
  });
}

function lineRow(model: IoPageModel, config: IoConfig, which: Which, line: Line, polarity: boolean): HTMLElement {
  const edit = (): LineEdit => model[which].val.get(line.name) ?? {};
  const testid = `io-${which === "inputs" ? "input" : "output"}-${line.name.split(" ")[0]}`;
  return h("tr", { "data-testid": testid },
    h("td", { title: line.physical ? "wired" : "virtual" }, line.name, line.physical ? "" : h("span", { class: "muted" }, " (virtual)")),
    h("td", null, functionPicker(model, which, line, choices(config, which, line), edit)),
    polarity ? h("td", null, line.inverted === null ? "" : h("input", {
      type: "checkbox",
      "data-testid": `${testid}-inverted`,
      checked: () => edit().inverted ?? line.inverted ?? false,
      onchange: (event: Event) => model.editLine(which, line.name, { inverted: (event.target as HTMLInputElement).checked }),
    })) : null,
    h("td", null, h("span", { "data-testid": `${testid}-live`, class: () => `led ${liveLevel(model, which, line) ? "on" : ""}` }, () => (liveLevel(model, which, line) ? "active" : "inactive"))));
}

function choices(config: IoConfig, which: Which, line: Line): IoFunction[] {
  const all = which === "inputs" ? config.functions : config.output_functions;
  const allowed = "allowed" in line ? new Set(line.allowed) : null;
  const listed = allowed ? all.filter((function_) => allowed.has(function_.key)) : all;
  return line.function === "other" ? [...listed, { key: "other", label: `other: 0x${(line.pointer ?? 0).toString(16).toUpperCase()}`, limit: 0, condition_bit: null }] : listed;
}

function functionPicker(model: IoPageModel, which: Which, line: Line, options: IoFunction[], edit: () => LineEdit): HTMLElement {
  return h("select", {
    "data-testid": `io-${which === "inputs" ? "input" : "output"}-${line.name.split(" ")[0]}-function`,
    value: () => edit().function ?? line.function,
    onchange: (event: Event) => model.editLine(which, line.name, { function: (event.target as HTMLSelectElement).value }),
  }, options.map((option) => h("option", { value: option.key, disabled: option.key === "other" }, option.label)));
}

function liveLevel(model: IoPageModel, which: Which, line: Line): boolean {
  const live = model.live.val;
  const levels = live ? (which === "inputs" ? live.input_levels : live.output_levels) : null;
  return Boolean(levels ? levels[line.name] : line.active);
}
