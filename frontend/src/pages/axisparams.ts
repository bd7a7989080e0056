/** Parameters of one axis: the dictionary editor wired to the drive (when online) and to the project files. */

import { projectAddress, projects, setParametersSkipping } from "../client/api";
import { toast } from "../components/ui";
import { driveApi, serverBus } from "../client/drives";
import { TerminalSocket } from "../client/terminal-socket";
import { LIVE_PERIOD_MS, type Watcher } from "../components/parameters/live";
import { entryKey } from "../lib/od";
import type { AxisContext, AxisViewPage } from "./axis";
import { ParameterEditor, type DriveCell } from "./parameters";

export async function parametersView(context: AxisContext): Promise<AxisViewPage> {
  const { project, axis, dictionary, page } = context;
  const hub = page.app.live;
  // Until the first state answer the axis is taken as online: reads are tried and a failure shows in the cells.
  const online = () => hub.axis(axis.bus, axis.node_id)?.online ?? true;
  const template = await projects.application(project.name, axis.name);
  const live = liveWatch(axis.bus, axis.node_id);
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
      watch: live.watch,
    },
    project: {
      load: async () => (await projects.parameters(project.name, axis.name)).parameters,
      write: async (changes) => {
        const values: Record<string, number | string> = {};
        for (const { entry, raw } of changes) values[projectAddress(entry.object.index, entry.variable.subindex)] = raw;
        // Many values at once (Drive → project): the project as it was stays restorable (a kept revision).
        const answer = await setParametersSkipping(project.name, axis.name, values, changes.length > 1);
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
  const unsubscribe = hub.onChange(() => {
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
      live.close();
    },
  };
}

/** The editor's live values through the server's terminal socket (opened on the first watch, one per editor). */
function liveWatch(bus: string, node: number): { watch: Watcher; close(): void } {
  let socket: TerminalSocket | null = null;
  const watch: Watcher = (list, onCells) => {
    if (!socket && list.length === 0) return;
    socket ??= new TerminalSocket();
    const keys = new Map(list.map((entry) => [projectAddress(entry.object.index, entry.variable.subindex), entry.key]));
    socket.onRows = (rows) => {
      const cells = new Map<string, DriveCell>();
      for (const row of rows) {
        const key = keys.get(row.object);
        if (key && row.value) cells.set(key, { raw: row.value.raw });
      }
      onCells(cells);
    };
    socket.watch([...keys.keys()].map((object) => ({ bus: serverBus(bus), node, object })), LIVE_PERIOD_MS);
  };
  return { watch, close: () => socket?.close() };
}
