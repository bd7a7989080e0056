/** Parameters of one axis: the dictionary editor wired to the drive (when online) and to the project files. */

import { projectAddress, projects, setParametersSkipping } from "../client/api";
import { toast } from "../components/ui";
import { driveApi } from "../client/drives";
import { entryKey } from "../lib/od";
import type { AxisContext, AxisViewPage } from "./axis";
import { ParameterEditor, type DriveCell } from "./parameters";

export async function parametersView(context: AxisContext): Promise<AxisViewPage> {
  const { project, axis, dictionary, page } = context;
  const live = page.app.live;
  // Until the first state answer the axis is taken as online: reads are tried and a failure shows in the cells.
  const online = () => live.axis(axis.bus, axis.node_id)?.online ?? true;
  const template = await projects.application(project.name, axis.name);
  const editor = new ParameterEditor(dictionary, {
    drive: {
      online,
      async read(entries, signal) {
        const values = await driveApi.readMany(axis.bus, axis.node_id, entries.map((e) => [e.object.index, e.variable.subindex]), signal);
        const cells = new Map<string, DriveCell>();
        for (const value of values) cells.set(entryKey(value.index, value.subindex), value.error ? { raw: null, error: value.error } : { raw: value.raw });
        return cells;
      },
      async write(entry, raw) {
        return driveApi.write(axis.bus, axis.node_id, entry.object.index, entry.variable.subindex, raw);
      },
    },
    project: {
      load: async () => (await projects.parameters(project.name, axis.name)).parameters,
      write: async (changes) => {
        const values: Record<string, number | string> = {};
        for (const { entry, raw } of changes) values[projectAddress(entry.object.index, entry.variable.subindex)] = raw;
        const answer = await setParametersSkipping(project.name, axis.name, values);
        if (answer.skipped.length) {
          if (changes.length === 1) throw new Error(answer.skipped[0]);
          toast(`${answer.skipped.length} values refused by the project: ${answer.skipped.slice(0, 3).join("; ")}`, "error");
        }
        return answer.parameters;
      },
      reset: async (entries) => {
        const addresses = entries.map((entry) => projectAddress(entry.object.index, entry.variable.subindex));
        return (await projects.resetParameters(project.name, axis.name, addresses)).parameters;
      },
    },
    onQuery: (query) => page.app.replaceQuery(query),
    application: template?.groups ? { title: template.title, groups: template.groups } : null,
  }, page.location);
  await editor.start();
  let wasOnline = online();
  const unsubscribe = live.onChange(() => {
    if (online() !== wasOnline) {
      wasOnline = online();
      editor.onlineChanged();
    }
  });
  return {
    element: editor.element,
    update: (location) => editor.update(location),
    focusSearch: () => editor.focusSearch(),
    dispose: () => {
      unsubscribe();
      editor.dispose();
    },
  };
}
