/** One project: its buses and axes (add, edit, remove), archive download, DCF export, compare. */

import type { Page, PageContext } from "../app";
import { listDictionaries, projects, type AxisConfig, type BusConfig, type Project } from "../client/api";
import { driveApi, serverBus, type BusInfo } from "../client/drives";
import { confirmAction, download, errorText, openDialog, toast } from "../components/ui";
import { h, replaceChildren } from "../lib/dom";
import { buildPath } from "../lib/router";
import { axisStateText } from "../client/live";
import { commissionPanel } from "../components/commissionjob";

export async function projectPage(context: PageContext, name: string): Promise<Page> {
  const { app } = context;
  let project = await projects.get(name);
  const devices = await listDictionaries();
  const deviceName = (key: string) => devices.find((d) => d.device === key)?.product_name ?? key;
  const axesBody = h("tbody");
  const busesBody = h("tbody");
  const description = h("span", { class: "muted" });
  const error = h("div");

  const changed = (next: Project) => {
    project = next;
    app.updateProject(next);
    render();
  };
  const guard = async (work: () => Promise<void>) => {
    try {
      replaceChildren(error);
      await work();
    } catch (failure) {
      replaceChildren(error, h("div", { class: "message error", "data-testid": "page-message" }, errorText(failure)));
    }
  };

  const axisDialog = (axis: AxisConfig | null) => {
    const dialog = openDialog(axis ? `Axis ${axis.name}` : "Add axis");
    const axisName = h("input", { type: "text", value: axis?.name ?? "", "data-testid": "axis-name" });
    const device = h("select", { "data-testid": "axis-device" }, devices.map((d) => h("option", { value: d.device }, d.product_name)));
    device.value = axis?.device ?? devices[0]?.device ?? "";
    const node = h("input", { type: "text", value: String(axis?.node_id ?? nextNode(project)), "data-testid": "axis-node", inputmode: "numeric" });
    const bus = h("select", { "data-testid": "axis-bus" }, project.buses.map((b) => h("option", { value: b.name }, `${b.name} (${b.interface})`)));
    bus.value = axis?.bus ?? project.buses[0]?.name ?? "";
    const text = h("input", { type: "text", value: axis?.description ?? "" });
    const message = h("div");
    dialog.body.append(
      h("div", { class: "grid cols-2" },
        h("label", { class: "field" }, "Axis name", axisName),
        h("label", { class: "field" }, "Device", device),
        h("label", { class: "field" }, "Node ID (1–63 on the switches)", node),
        h("label", { class: "field" }, "Bus", bus)),
      h("label", { class: "field" }, "Description", text), message);
    const submit = async () => {
      const nodeId = Number(node.value);
      if (!Number.isInteger(nodeId)) {
        replaceChildren(message, h("div", { class: "message error" }, `Node ID "${node.value}" is not a whole number`));
        return;
      }
      try {
        const values = { name: axisName.value.trim(), device: device.value, node_id: nodeId, bus: bus.value, description: text.value };
        const next = axis
          ? await projects.editAxis(project.name, axis.name, { ...values, revision: project.revision })
          : await projects.addAxis(project.name, values, project.revision);
        dialog.close();
        changed(next);
      } catch (failure) {
        replaceChildren(message, h("div", { class: "message error", "data-testid": "dialog-error" }, errorText(failure)));
      }
    };
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"),
      h("button", { class: "primary", "data-testid": "save-axis", onclick: submit }, axis ? "Save" : "Add axis"));
    axisName.focus();
  };

  const removeAxis = async (axis: AxisConfig) => {
    if (!(await confirmAction("Remove axis", `Remove axis ${axis.name} and its parameter files from project ${project.name}?`, "Remove", true))) return;
    await guard(async () => changed(await projects.removeAxis(project.name, axis.name, project.revision)));
  };

  const busDialog = () => {
    const dialog = openDialog("Buses of the project");
    const rows = project.buses.map((b) => ({ name: h("input", { type: "text", value: b.name }), spec: h("input", { type: "text", value: b.interface }) }));
    const list = h("div", { class: "grid", style: { gap: "6px" } });
    const draw = () => replaceChildren(list, rows.map((row) => h("div", { class: "grid cols-2" }, row.name, row.spec)));
    draw();
    const message = h("div");
    dialog.body.append(h("div", { class: "grid cols-2 muted" }, h("span", null, "Name"), h("span", null, "Bus spec")), list,
      h("button", { class: "small", onclick: () => { rows.push({ name: h("input", { type: "text" }), spec: h("input", { type: "text", value: "sim" }) }); draw(); } }, "Add bus"), message);
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), h("button", {
      class: "primary", onclick: async () => {
        try {
          const buses = rows.filter((r) => r.name.value.trim()).map((r) => ({ name: r.name.value.trim(), interface: r.spec.value.trim(), bitrate: null }));
          changed(await projects.update(project.name, { buses, revision: project.revision }));
          dialog.close();
        } catch (failure) {
          replaceChildren(message, h("div", { class: "message error" }, errorText(failure)));
        }
      },
    }, "Save"));
  };

  const renameOrCopy = (copy: boolean) => {
    const dialog = openDialog(copy ? "Duplicate project" : "Rename project");
    const input = h("input", { type: "text", value: copy ? `${project.name}-copy` : project.name });
    const message = h("div");
    dialog.body.append(h("label", { class: "field" }, "New name", input), message);
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), h("button", {
      class: "primary", onclick: async () => {
        try {
          const next = copy ? await projects.duplicate(project.name, input.value.trim()) : await projects.rename(project.name, input.value.trim(), project.revision);
          dialog.close();
          await app.refreshProjects();
          app.navigate({ page: "project", project: next.name });
        } catch (failure) {
          replaceChildren(message, h("div", { class: "message error" }, errorText(failure)));
        }
      },
    }, copy ? "Duplicate" : "Rename"));
    input.focus();
  };

  const deleteProject = async () => {
    if (!(await confirmAction("Delete project", `Delete project ${project.name} with all its axis files? Archive it first if you may need it again.`, "Delete", true))) return;
    await guard(async () => {
      await projects.remove(project.name, project.revision);
      toast(`Project ${project.name} deleted`, "ok");
      await app.refreshProjects();
      app.navigate({ page: "home" });
    });
  };

  let serverBuses: BusInfo[] = [];
  const openBus = (bus: BusConfig) => guard(async () => {
    await driveApi.openBus(bus.interface, bus.name);
    await app.refreshBuses();
    await loadBuses();
    await app.live.refreshAxes();
  });
  const busCell = (bus: BusConfig) => {
    const open = serverBuses.find((candidate) => candidate.id === serverBus(bus.name));
    if (open) return h("span", { class: open.connected ? "ok-text" : "error-text" }, `${open.connected ? "connected" : "disconnected"} as ${open.id}`);
    return h("span", { class: "toolbar" }, h("span", { class: "muted" }, "not open"),
      h("button", { class: "small primary", "data-testid": `open-bus-${bus.name}`, onclick: () => void openBus(bus) }, "Connect"));
  };
  const loadBuses = async () => {
    serverBuses = await driveApi.buses().catch(() => []);
    render();
  };

  const render = () => {
    description.textContent = project.description;
    replaceChildren(busesBody, project.buses.length ? project.buses.map((b) => h("tr", null,
      h("td", null, b.name), h("td", { class: "mono" }, b.interface), h("td", { class: "num" }, b.bitrate ? `${b.bitrate / 1000} kbit/s` : ""),
      h("td", null, busCell(b))))
      : h("tr", null, h("td", { colspan: "4", class: "muted" }, "No bus: add one before adding axes.")));
    replaceChildren(axesBody, project.axes.length ? project.axes.map((axis) => {
      const state = axisStateText(app.live.axis(axis.bus, axis.node_id));
      const link = (view: "dashboard" | "parameters" | "commissioning", label: string) =>
        h("a", { href: buildPath({ page: "axis", project: project.name, axis: axis.name, view }) }, label);
      return h("tr", { "data-testid": `axis-row-${axis.name}` },
        h("td", null, link("dashboard", axis.name)),
        h("td", null, deviceName(axis.device)),
        h("td", { class: "num" }, String(axis.node_id)),
        h("td", null, axis.bus),
        h("td", null, h("span", { class: `dot ${state.tone}` }), " ", state.text),
        h("td", null, axis.motor || h("span", { class: "muted" }, "none")),
        h("td", { class: "wrap" }, axis.description),
        h("td", null, h("span", { class: "toolbar" }, link("parameters", "Parameters"), link("commissioning", "Checklist"),
          h("button", { class: "small", onclick: () => download(projects.dcfUrl(project.name, axis.name)), title: "Export the project values as a CiA 306 DCF" }, "DCF"),
          h("button", { class: "small", onclick: () => axisDialog(axis) }, "Edit"),
          h("button", { class: "small danger", onclick: () => removeAxis(axis) }, "Remove"))));
    }) : h("tr", null, h("td", { colspan: "8", class: "muted" }, "No axis yet: add one per drive (device, node ID, bus).")));
  };
  render();
  await loadBuses();
  const unsubscribe = app.live.onChange(render);

  return {
    title: project.name,
    crumbs: [h("a", { href: "/" }, "Projects"), ` / ${project.name}`],
    dispose: unsubscribe,
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", { "data-testid": "project-title" }, project.name), description),
      h("div", { class: "toolbar" },
        h("button", { class: "primary", "data-testid": "add-axis", onclick: () => axisDialog(null), disabled: project.buses.length === 0 }, "Add axis…"),
        h("a", { class: "button", href: buildPath({ page: "compare", project: project.name }) }, "Compare"),
        h("button", { onclick: busDialog }, "Buses…"),
        h("button", { "data-testid": "archive", onclick: () => download(projects.archiveUrl(project.name)), title: "Download the project as one .zip file" }, "Archive"),
        h("button", { onclick: () => renameOrCopy(false) }, "Rename…"),
        h("button", { onclick: () => renameOrCopy(true) }, "Duplicate…"),
        h("button", { class: "danger", onclick: deleteProject }, "Delete…")),
      error,
      h("div", { class: "panel" }, h("h2", null, "Axes"), h("table", { class: "data", "data-testid": "axes-table" },
        h("thead", null, h("tr", null, ["Axis", "Device", "Node", "Bus", "State", "Motor", "Description", ""].map((t) => h("th", null, t)))),
        axesBody)),
      commissionPanel(app, project.name, () => void projects.get(project.name).then(changed)),
      h("div", { class: "panel" }, h("h2", null, "Buses"), h("table", { class: "data" },
        h("thead", null, h("tr", null, h("th", null, "Name"), h("th", null, "Spec"), h("th", { class: "num" }, "Bit rate"), h("th", null, "Server"))), busesBody))),
  };
}

function nextNode(project: Project): number {
  const used = new Set(project.axes.map((axis) => axis.node_id));
  let node = 1;
  while (used.has(node)) node++;
  return node;
}
