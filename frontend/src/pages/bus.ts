/** Buses: connect by spec string, scan, add found drives to a project, NMT broadcast, close. */

import type { Page, PageContext } from "../app";
import { projects, type Project } from "../client/api";
import { confirmAction, errorText, openDialog, toast } from "../components/ui";
import { driveApi, type BusInfo, type NodeIdentity } from "../client/drives";
import { h, replaceChildren } from "../lib/dom";
import { formatHex } from "../lib/numbers";
import { buildPath } from "../lib/router";

const SPEC_EXAMPLES = [
  "sim", "socketcan:can0", "pcan:PCAN_USBBUS1@1000000", "ixxat:0@500000", "kvaser:0",
  "slcan:/dev/ttyACM0@1000000", "socketcand:127.0.0.1:29536", "serial:/dev/ttyUSB0@19200",
];

export async function busPage(context: PageContext): Promise<Page> {
  const { app } = context;
  await app.projectsReady;
  const spec = h("input", { type: "text", list: "bus-specs", style: { width: "300px" }, "data-testid": "bus-spec", "aria-label": "Bus spec", spellcheck: "false" });
  const busId = h("input", { type: "text", style: { width: "120px" }, "data-testid": "bus-id", "aria-label": "Bus name", placeholder: "name (optional)" });
  const list = h("div", { class: "grid", style: { gap: "12px" } });
  const message = h("div");
  const scanned = new Map<string, NodeIdentity[]>();

  const load = async () => {
    const buses = await driveApi.buses();
    replaceChildren(list, buses.length ? buses.map(busPanel) : h("div", { class: "panel empty-state" }, "No bus is open. Connect one above."));
  };

  const busPanel = (bus: BusInfo): HTMLElement => {
    const nodes = scanned.get(bus.id) ?? bus.nodes;
    const body = h("tbody", null, nodes.length ? nodes.map((node) => h("tr", { "data-testid": `scan-node-${node.node}` },
      h("td", { class: "num" }, String(node.node)),
      h("td", null, node.device_name ?? ""),
      h("td", null, node.device ?? h("span", { class: "warn-text" }, "no dictionary")),
      h("td", { class: "mono" }, node.vendor_id === null ? "" : formatHex(node.vendor_id, 8)),
      h("td", { class: "mono" }, node.product_code === null ? "" : formatHex(node.product_code, 8)),
      h("td", { class: "mono" }, node.revision === null ? "" : formatHex(node.revision, 8)),
      h("td", { class: "mono" }, node.serial_number === null ? "" : String(node.serial_number)),
      h("td", null, node.software_version ?? ""),
      h("td", null, h("button", { class: "small", disabled: !node.device, "data-testid": `add-node-${node.node}`, onclick: () => addToProject(bus, [node]) }, "Add to project…"))))
      : h("tr", null, h("td", { colspan: "9", class: "muted" }, "No node known yet: scan the bus.")));
    return h("section", { class: "panel", "data-testid": `bus-${bus.id}` },
      h("h2", null, `${bus.id} · ${bus.spec}`,
        h("span", { class: "right toolbar" },
          h("span", { class: bus.connected ? "ok-text" : "error-text" }, bus.connected ? "connected" : `disconnected${bus.error ? `: ${bus.error}` : ""}`),
          h("button", { class: "small primary", "data-testid": `scan-${bus.id}`, onclick: (event: Event) => scan(bus, event.target as HTMLButtonElement) }, "Scan"),
          h("button", { class: "small", disabled: nodes.filter((n) => n.device).length === 0, onclick: () => addToProject(bus, nodes.filter((n) => n.device)) }, "Add all to project…"),
          h("button", { class: "small", title: "NMT start, all nodes", onclick: () => nmt(bus, "start") }, "NMT start all"),
          h("button", { class: "small", title: "NMT pre-operational, all nodes", onclick: () => nmt(bus, "pre-operational") }, "Pre-op all"),
          h("button", { class: "small danger", onclick: () => close(bus) }, "Close"))),
      h("table", { class: "data" },
        h("thead", null, h("tr", null, ["Node", "Device name", "Dictionary", "Vendor", "Product", "Revision", "Serial", "Software", ""].map((t) => h("th", null, t)))),
        body));
  };

  const guard = async (work: () => Promise<void>) => {
    replaceChildren(message);
    try {
      await work();
    } catch (error) {
      replaceChildren(message, h("div", { class: "message error", "data-testid": "bus-error" }, errorText(error)));
    }
  };

  const connect = () => guard(async () => {
    const bus = await driveApi.openBus(spec.value.trim(), busId.value.trim() || undefined);
    toast(`Bus ${bus.id} opened (${bus.spec})`, "ok");
    await load();
    await app.refreshBuses();
  });

  const scan = (bus: BusInfo, button: HTMLButtonElement) => guard(async () => {
    button.disabled = true;
    button.textContent = "Scanning…";
    try {
      const found = await driveApi.scan(bus.id);
      scanned.set(bus.id, found);
      toast(`${found.length} node${found.length === 1 ? "" : "s"} found on ${bus.id}`, "ok");
    } finally {
      await load();
    }
  });

  const nmt = (bus: BusInfo, command: string) => guard(async () => {
    await driveApi.nmt(bus.id, command, 0);
    toast(`NMT ${command} sent to every node of ${bus.id}`, "ok");
  });

  const close = async (bus: BusInfo) => {
    if (!(await confirmAction("Close bus", `Close bus ${bus.id}? Its drives go offline in the tool (they keep running).`, "Close bus"))) return;
    await guard(async () => {
      await driveApi.closeBus(bus.id);
      await load();
      await app.refreshBuses();
    });
  };

  const addToProject = (bus: BusInfo, nodes: NodeIdentity[]) => {
    const known = app.projectsLoaded();
    const dialog = openDialog(nodes.length === 1 ? `Add node ${nodes[0].node} to a project` : `Add ${nodes.length} nodes to a project`);
    const target = h("select", { "data-testid": "add-project" }, known.map((p) => h("option", { value: p.name }, p.name)));
    const names = nodes.map((node) => h("input", { type: "text", value: `${node.device ?? "axis"}-${node.node}`.replace(/[^A-Za-z0-9_-]/g, "") }));
    const text = h("div");
    dialog.body.append(
      known.length ? h("label", { class: "field" }, "Project", target) : h("div", { class: "message warn" }, "Create a project first (Projects page)."),
      h("div", { class: "muted" }, `The axes use the project's bus with spec "${bus.spec}"; a project without one gets a bus "${bus.id}".`),
      h("table", { class: "data" }, h("thead", null, h("tr", null, h("th", null, "Node"), h("th", null, "Device"), h("th", null, "Axis name"))),
        h("tbody", null, nodes.map((node, i) => h("tr", null, h("td", { class: "num" }, String(node.node)), h("td", null, node.device ?? ""), h("td", null, names[i]))))),
      text);
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), h("button", {
      class: "primary", disabled: known.length === 0, "data-testid": "add-confirm", onclick: async () => {
        try {
          let project: Project = await projects.get(target.value);
          // The project's own bus of that name or spec, else a new project bus named like the server's.
          let projectBus = project.buses.find((b) => b.name === bus.id) ?? project.buses.find((b) => b.interface === bus.spec);
          if (!projectBus) {
            projectBus = { name: bus.id, interface: bus.spec, bitrate: null };
            project = await projects.update(project.name, { buses: [...project.buses, projectBus], revision: project.revision });
          }
          for (const [i, node] of nodes.entries()) {
            project = await projects.addAxis(project.name, { name: names[i].value.trim(), device: node.device!, node_id: node.node, bus: projectBus.name, description: node.device_name ?? "" }, project.revision);
          }
          app.updateProject(project);
          dialog.close();
          toast(`${nodes.length} axis${nodes.length === 1 ? "" : "es"} added to ${project.name}`, "ok");
          app.navigate({ page: "project", project: project.name });
        } catch (error) {
          replaceChildren(text, h("div", { class: "message error", "data-testid": "dialog-error" }, errorText(error)));
        }
      },
    }, "Add"));
  };

  await load();
  spec.addEventListener("keydown", (event) => event.key === "Enter" && void connect());
  const projectBuses = app.projectsLoaded().flatMap((project: Project) => project.buses.map((b) => ({ project: project.name, bus: b })));
  return {
    title: "Bus",
    focusSearch: () => { spec.focus(); return true; },
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Buses and scan")),
      h("datalist", { id: "bus-specs" }, SPEC_EXAMPLES.map((example) => h("option", { value: example }))),
      h("div", { class: "toolbar" }, h("span", null, "Bus spec"), spec, busId,
        h("button", { class: "primary", "data-testid": "bus-connect", onclick: () => void connect() }, "Connect"),
        h("span", { class: "muted" }, "e.g. sim, socketcan:can0, serial:/dev/ttyUSB0@19200")),
      projectBuses.length ? h("div", { class: "toolbar" }, h("span", { class: "muted" }, "Buses of the projects:"),
        projectBuses.map(({ project, bus }) => h("button", {
          class: "small", title: `Open bus ${bus.name} of project ${project} (${bus.interface})`,
          onclick: () => { spec.value = bus.interface; busId.value = bus.name; void connect(); },
        }, `${project}: ${bus.name} (${bus.interface})`))) : null,
      message, list,
      h("p", { class: "muted", style: { margin: "0" } }, "Axes reach their drive through the bus of the same name; open a project's buses here, then its axes go online. ",
        h("a", { href: buildPath({ page: "terminal" }) }, "Dialog terminal"), " reads and writes any object.")),
  };
}
