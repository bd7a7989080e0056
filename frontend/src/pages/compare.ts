/**
 * Compare: the project values of an axis against the defaults and the drive, or of several axes against each
 * other (same device), with the differing rows marked.
 */

import type { Page, PageContext } from "../app";
import { getDictionary, projects, type Project } from "../client/api";
import { driveApi } from "../client/drives";
import { errorText } from "../components/ui";
import { h, replaceChildren } from "../lib/dom";
import { entries, entryKey, type Entry, type Scalar } from "../lib/od";
import { buildPath } from "../lib/router";
import { formatValue, sameValue } from "../lib/values";

export async function comparePage(context: PageContext, name: string): Promise<Page> {
  const { app } = context;
  const project: Project = await projects.get(name);
  const chosen = new Set(project.axes.slice(0, 2).map((axis) => axis.name));
  const withDrive = h("input", { type: "checkbox", "data-testid": "compare-drive" });
  const withDefault = h("input", { type: "checkbox", checked: true });
  const onlyDiff = h("input", { type: "checkbox", checked: true, "data-testid": "compare-only-diff" });
  const groupFilter = h("input", { type: "search", placeholder: "Filter by name or index", style: { width: "220px" } });
  const table = h("div", { class: "panel", style: { overflow: "auto" } });
  const summary = h("span", { class: "muted", "data-testid": "compare-summary" });
  const boxes = project.axes.map((axis) => {
    const box = h("input", { type: "checkbox", checked: chosen.has(axis.name), "data-testid": `compare-axis-${axis.name}` });
    box.addEventListener("change", () => {
      if (box.checked) chosen.add(axis.name);
      else chosen.delete(axis.name);
      void load();
    });
    return h("label", { class: "check" }, box, axis.name);
  });
  let token = 0;

  const load = async () => {
    const mine = ++token;
    const axes = project.axes.filter((axis) => chosen.has(axis.name));
    if (axes.length === 0) {
      replaceChildren(table, h("div", { class: "empty-state" }, "Choose at least one axis."));
      summary.textContent = "";
      return;
    }
    replaceChildren(table, h("div", { class: "empty-state" }, "Loading values…"));
    try {
      const devices = new Set(axes.map((axis) => axis.device));
      if (devices.size > 1) throw new Error(`The chosen axes use different devices (${[...devices].join(", ")}): compare axes of one device.`);
      const dictionary = await getDictionary(axes[0].device);
      const list = entries(dictionary);
      const columns: { title: string; values: Map<string, Scalar> }[] = [];
      for (const axis of axes) {
        const rows = (await projects.parameters(project.name, axis.name)).parameters;
        columns.push({ title: `${axis.name} project`, values: new Map(rows.map((row) => [entryKey(row.index, row.subindex), row.value])) });
        if (withDrive.checked && app.live.axis(axis.bus, axis.node_id)?.online) {
          const keys = rows.filter((row) => row.access !== "wo").map((row) => [row.index, row.subindex] as [number, number]);
          const values = await driveApi.readMany(axis.bus, axis.node_id, keys);
          columns.push({ title: `${axis.name} drive`, values: new Map(values.filter((v) => !v.error).map((v) => [entryKey(v.index, v.subindex), v.raw])) });
        }
      }
      if (mine !== token) return;
      if (withDefault.checked) columns.push({ title: "default", values: new Map(list.map((entry) => [entry.key, entry.variable.default])) });
      const filter = groupFilter.value.trim().toLowerCase();
      const rows = list.filter((entry) => columns.some((column) => column.values.has(entry.key)))
        .filter((entry) => !filter || entry.variable.name.toLowerCase().includes(filter) || entry.object.name.toLowerCase().includes(filter)
          || entry.object.index.toString(16).includes(filter.replace(/^0x/, "")));
      const differing = (entry: Entry) => {
        const values = columns.filter((c) => c.values.has(entry.key)).map((c) => c.values.get(entry.key) ?? null);
        return values.some((value) => !sameValue(value, values[0]));
      };
      const shown = onlyDiff.checked ? rows.filter(differing) : rows;
      summary.textContent = `${shown.length} rows shown · ${rows.filter(differing).length} of ${rows.length} differ`;
      replaceChildren(table, h("table", { class: "data", "data-testid": "compare-table" },
        h("thead", null, h("tr", null, h("th", null, "Index"), h("th", null, "Name"), h("th", null, "Unit"), columns.map((c) => h("th", { class: "num" }, c.title)))),
        h("tbody", null, shown.slice(0, 2000).map((entry) => h("tr", { class: differing(entry) ? "differs" : "" },
          h("td", { class: "mono" }, `0x${entry.object.index.toString(16).toUpperCase().padStart(4, "0")}.${entry.variable.subindex}`),
          h("td", { class: "wrap", style: { minWidth: "220px" } }, entry.variable.name === entry.object.name ? entry.variable.name : `${entry.object.name} › ${entry.variable.name}`),
          h("td", { class: "muted" }, entry.variable.unit),
          columns.map((c) => h("td", { class: "num mono" }, c.values.has(entry.key) ? formatValue(entry.variable, c.values.get(entry.key)) : "")))))));
    } catch (error) {
      if (mine === token) replaceChildren(table, h("div", { class: "message error" }, errorText(error)));
    }
  };
  for (const input of [withDrive, withDefault, onlyDiff]) input.addEventListener("change", () => void load());
  let timer = 0;
  groupFilter.addEventListener("input", () => {
    clearTimeout(timer);
    timer = window.setTimeout(() => void load(), 150);
  });
  await load();
  return {
    title: `Compare ${project.name}`,
    crumbs: [h("a", { href: "/" }, "Projects"), " / ", h("a", { href: buildPath({ page: "project", project: project.name }) }, project.name), " / Compare"],
    focusSearch: () => { groupFilter.focus(); return true; },
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Compare"), summary),
      h("div", { class: "toolbar" }, h("span", { class: "muted" }, "Axes:"), boxes,
        h("span", { class: "muted" }, "·"), h("label", { class: "check" }, withDrive, "drive values"),
        h("label", { class: "check" }, withDefault, "defaults"), h("label", { class: "check" }, onlyDiff, "only differences"),
        groupFilter),
      table),
  };
}
