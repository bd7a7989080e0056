/** Projects: list, create, open, import an archive. */

import type { Page, PageContext } from "../app";
import { ApiError, listDictionaries, projects, type Project } from "../client/api";
import { errorText, openDialog, pickFile, toast } from "../components/ui";
import { h, replaceChildren } from "../lib/dom";
import { buildPath } from "../lib/router";

export async function homePage(context: PageContext): Promise<Page> {
  const { app } = context;
  const body = h("tbody");
  const load = async () => {
    const list = await projects.list();
    if (list.length === 0) {
      replaceChildren(body, h("tr", null, h("td", { colspan: "3", class: "muted" }, "No project in the project directory. Create one or import an archive.")));
      return;
    }
    replaceChildren(body, list.map((project) => h("tr", { "data-testid": `project-row-${project.name}` },
      h("td", null, h("a", { href: buildPath({ page: "project", project: project.name }) }, project.name)),
      h("td", { class: "wrap" }, project.description),
      h("td", { class: "num" }, String(project.axis_count)))));
  };
  await load();

  const create = () => {
    const dialog = openDialog("New project");
    const name = h("input", { type: "text", "data-testid": "new-project-name", autocomplete: "off" });
    const description = h("input", { type: "text", "data-testid": "new-project-description" });
    const busName = h("input", { type: "text", value: "sim" });
    const busSpec = h("input", { type: "text", value: "sim", "data-testid": "new-project-bus" });
    const error = h("div");
    dialog.body.append(
      h("label", { class: "field" }, "Name (also the directory name)", name),
      h("label", { class: "field" }, "Description", description),
      h("div", { class: "grid cols-2" },
        h("label", { class: "field" }, "Bus name", busName),
        h("label", { class: "field" }, "Bus spec (sim, socketcan:can0, serial:/dev/ttyUSB0…)", busSpec)),
      error);
    const submit = async () => {
      try {
        const buses = busName.value.trim() ? [{ name: busName.value.trim(), interface: busSpec.value.trim(), bitrate: null }] : [];
        const project = await projects.create(name.value.trim(), description.value.trim(), buses);
        dialog.close();
        app.updateProject(project);
        app.navigate({ page: "project", project: project.name });
      } catch (failure) {
        replaceChildren(error, h("div", { class: "message error", "data-testid": "dialog-error" }, errorText(failure)));
      }
    };
    name.addEventListener("keydown", (event) => event.key === "Enter" && void submit());
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"),
      h("button", { class: "primary", "data-testid": "create-project", onclick: submit }, "Create"));
    name.focus();
  };

  const imported = (project: Project) => {
    toast(`Project "${project.name}" imported`, "ok");
    app.updateProject(project);
    app.navigate({ page: "project", project: project.name });
  };

  /** The archive names a project that exists already: ask for another name and import under it. */
  const importAs = (file: File, reason: string) => {
    const dialog = openDialog("Import archive");
    const name = h("input", { type: "text", "data-testid": "import-name", value: `${file.name.replace(/\.zip$/i, "")}-imported` });
    const message = h("div");
    dialog.body.append(h("div", { class: "message warn" }, reason), h("label", { class: "field" }, "Import as project", name), message);
    dialog.actions.append(h("button", { onclick: () => dialog.close() }, "Cancel"), h("button", {
      class: "primary", "data-testid": "import-confirm", onclick: async () => {
        try {
          const project = await projects.unarchive(file, name.value.trim());
          dialog.close();
          imported(project);
        } catch (error) {
          replaceChildren(message, h("div", { class: "message error", "data-testid": "dialog-error" }, errorText(error)));
        }
      },
    }, "Import"));
    name.focus();
  };

  const unarchive = async () => {
    const file = await pickFile(".zip,application/zip");
    if (!file) return;
    try {
      imported(await projects.unarchive(file));
    } catch (error) {
      if (error instanceof ApiError && error.status === 409) importAs(file, errorText(error));
      else toast(`Import failed: ${errorText(error)}`, "error");
    }
  };

  const devices = await listDictionaries().catch(() => []);
  return {
    title: "Servo Studio",
    crumbs: ["Projects"],
    element: h("div", { class: "page" },
      h("div", { class: "page-head" }, h("h1", null, "Projects"),
        h("button", { class: "primary", "data-testid": "new-project", onclick: create }, "New project…"),
        h("button", { onclick: unarchive, "data-testid": "unarchive", title: "Import a project archive (.zip) made with Archive" }, "Import archive…")),
      h("div", { class: "panel" }, h("table", { class: "data" },
        h("thead", null, h("tr", null, h("th", null, "Project"), h("th", null, "Description"), h("th", { class: "num" }, "Axes"))),
        body)),
      h("div", { class: "panel" }, h("h2", null, "Supported devices"),
        h("div", { class: "panel-body" }, devices.length
          ? devices.map((device, i) => [i ? " · " : "", h("a", { href: buildPath({ page: "dictionary", device: device.device }) }, device.product_name)])
          : h("span", { class: "muted" }, "The dictionary library is empty.")))),
  };
}
