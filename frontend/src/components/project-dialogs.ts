/** Dialogs of the project page: add or edit an axis, the project's buses, rename or duplicate the project. */

import type { App } from "../app";
import { projects, type AxisConfig, type BusConfig, type Project } from "../client/api";
import { h, state } from "../lib/dom";
import type { DictionarySummary } from "../lib/od";
import { formDialog } from "./ui";

/** Add an axis (`axis` null) or edit one; `changed` gets the project the server answered. */
export function axisDialog(project: Project, devices: DictionarySummary[], axis: AxisConfig | null, changed: (next: Project) => void): void {
  const axisName = h("input", { type: "text", value: axis?.name ?? "", "data-testid": "axis-name" });
  const device = h("select", { "data-testid": "axis-device" }, devices.map((d) => h("option", { value: d.device }, d.product_name)));
  device.value = axis?.device ?? devices[0]?.device ?? "";
  const node = h("input", { type: "text", value: String(axis?.node_id ?? nextNode(project)), "data-testid": "axis-node", inputmode: "numeric" });
  const bus = h("select", { "data-testid": "axis-bus" }, project.buses.map((b) => h("option", { value: b.name }, `${b.name} (${b.interface})`)));
  bus.value = axis?.bus ?? project.buses[0]?.name ?? "";
  const text = h("input", { type: "text", value: axis?.description ?? "" });
  formDialog({
    title: axis ? `Axis ${axis.name}` : "Add axis",
    body: [
      h("div", { class: "grid cols-2" },
        h("label", { class: "field" }, "Axis name", axisName),
        h("label", { class: "field" }, "Device", device),
        h("label", { class: "field" }, "Node ID (1–63 on the switches)", node),
        h("label", { class: "field" }, "Bus", bus)),
      h("label", { class: "field" }, "Description", text),
    ],
    confirm: axis ? "Save" : "Add axis",
    confirmTestid: "save-axis",
    errorTestid: "dialog-error",
    submit: async () => {
      const nodeId = Number(node.value);
      if (!Number.isInteger(nodeId)) throw new Error(`Node ID "${node.value}" is not a whole number`);
      const values = { name: axisName.value.trim(), device: device.value, node_id: nodeId, bus: bus.value, description: text.value };
      changed(axis
        ? await projects.editAxis(project.name, axis.name, { ...values, revision: project.revision })
        : await projects.addAxis(project.name, values, project.revision));
    },
  });
  axisName.focus();
}

/** The lowest node ID no axis of the project uses. */
export function nextNode(project: Project): number {
  const used = new Set(project.axes.map((axis) => axis.node_id));
  let node = 1;
  while (used.has(node)) node++;
  return node;
}

interface BusRow {
  name: HTMLInputElement;
  spec: HTMLInputElement;
}

const busRow = (bus?: BusConfig): BusRow => ({
  name: h("input", { type: "text", value: bus?.name ?? "" }),
  spec: h("input", { type: "text", value: bus?.interface ?? "sim" }),
});

/** Edit the project's buses (name and spec); rows without a name are dropped. */
export function busesDialog(project: Project, changed: (next: Project) => void): void {
  const rows = state<BusRow[]>(project.buses.map(busRow));
  formDialog({
    title: "Buses of the project",
    body: [
      h("div", { class: "grid cols-2 muted" }, h("span", null, "Name"), h("span", null, "Bus spec")),
      h("div", { class: "grid", style: { gap: "6px" } }, () => rows.val.map((row) => h("div", { class: "grid cols-2" }, row.name, row.spec))),
      h("button", { class: "small", onclick: () => (rows.val = [...rows.val, busRow()]) }, "Add bus"),
    ],
    confirm: "Save",
    submit: async () => {
      const buses = rows.rawVal.filter((r) => r.name.value.trim()).map((r) => ({ name: r.name.value.trim(), interface: r.spec.value.trim(), bitrate: null }));
      changed(await projects.update(project.name, { buses, revision: project.revision }));
    },
  });
}

/** Rename the project or save a copy under another name, then open it. */
export function renameDialog(app: App, project: Project, copy: boolean): void {
  const input = h("input", { type: "text", value: copy ? `${project.name}-copy` : project.name });
  formDialog({
    title: copy ? "Duplicate project" : "Rename project",
    body: [h("label", { class: "field" }, "New name", input)],
    confirm: copy ? "Duplicate" : "Rename",
    submit: async () => {
      const name = input.value.trim();
      const next = copy ? await projects.duplicate(project.name, name) : await projects.rename(project.name, name, project.revision);
      await app.refreshProjects();
      app.navigate({ page: "project", project: next.name });
    },
  });
  input.focus();
}
