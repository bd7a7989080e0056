/**
 * The values the parameter editor shows, one reactive cell per entry: the drive value (read lazily, as rows come
 * into view) and the project row. Rows, the detail pane and the bulk buttons bind to these cells, so storing a
 * value is all it takes to show it.
 */

import type { ProjectParameter } from "../../client/api";
import { errorText } from "../ui";
import { batch, state, type State } from "../../lib/dom";
import { entryKey, isReadable, isWritable, type Entry, type Scalar } from "../../lib/od";
import { sameValue } from "../../lib/values";

export interface DriveCell {
  raw: Scalar;
  error?: string;
}

/** Reads a batch of drive values (the axis's `POST …/read`). */
export type DriveReader = (entries: Entry[], signal: AbortSignal) => Promise<Map<string, DriveCell>>;

const READ_CHUNK = 40;

export class ParameterStore {
  /** Whether the drive answers: reads and drive writes are offered only then. */
  readonly online: State<boolean>;
  private readonly drive = new Map<string, State<DriveCell | undefined>>();
  private readonly project = new Map<string, State<ProjectParameter | undefined>>();

  constructor(
    online: boolean,
    private readonly reader: DriveReader | null,
  ) {
    this.online = state(online);
  }

  driveCell(key: string): State<DriveCell | undefined> {
    let cell = this.drive.get(key);
    if (!cell) this.drive.set(key, (cell = state<DriveCell | undefined>(undefined)));
    return cell;
  }

  projectRow(key: string): State<ProjectParameter | undefined> {
    let row = this.project.get(key);
    if (!row) this.project.set(key, (row = state<ProjectParameter | undefined>(undefined)));
    return row;
  }

  setProjectRows(rows: ProjectParameter[]): void {
    batch(() => {
      for (const row of rows) this.projectRow(entryKey(row.index, row.subindex)).val = row;
    });
  }

  /** The value an editor starts from: the drive's, else the project's, else the default. */
  current(entry: Entry): Scalar {
    return this.driveCell(entry.key).val?.raw ?? this.projectRow(entry.key).val?.value ?? entry.variable.default;
  }

  differs(entry: Entry): boolean {
    const cell = this.driveCell(entry.key).val;
    const row = this.projectRow(entry.key).val;
    if (!cell || cell.error || !row || row.value === null) return false;
    return !sameValue(cell.raw, row.value);
  }

  /** Readable entries whose drive value was not read yet. */
  unread(list: Entry[]): Entry[] {
    return list.filter((entry) => isReadable(entry.variable.access) && this.driveCell(entry.key).val === undefined);
  }

  /** Project values set in the files that differ from the drive (Write changed → drive). */
  toDrive(list: Entry[]): Entry[] {
    return list.filter((entry) => this.projectRow(entry.key).val?.file && this.differs(entry) && isWritable(entry.variable.access));
  }

  /** Differing drive values the project can take (Drive → project). */
  toProject(list: Entry[]): Entry[] {
    return list.filter((entry) => this.differs(entry) && this.projectRow(entry.key).val?.editable);
  }

  /** Entries the project files set (Reset to defaults). */
  explicit(list: Entry[]): Entry[] {
    return list.filter((entry) => this.projectRow(entry.key).val?.file);
  }

  forget(list: Entry[]): void {
    batch(() => {
      for (const entry of list) this.driveCell(entry.key).val = undefined;
    });
  }

  /** Read the drive values of `list` in batches; a failed batch marks its entries with the error. */
  async read(list: Entry[], signal: AbortSignal, progress?: (done: number) => void): Promise<void> {
    const reader = this.reader;
    if (!reader) return;
    const readable = list.filter((entry) => isReadable(entry.variable.access));
    for (let start = 0; start < readable.length; start += READ_CHUNK) {
      if (signal.aborted) return;
      const chunk = readable.slice(start, start + READ_CHUNK);
      let cells: Map<string, DriveCell>;
      try {
        cells = await reader(chunk, signal);
      } catch (error) {
        if (signal.aborted) return;
        cells = new Map(chunk.map((entry) => [entry.key, { raw: null, error: errorText(error) }]));
      }
      batch(() => {
        for (const [key, cell] of cells) this.driveCell(key).val = cell;
      });
      progress?.(Math.min(readable.length, start + READ_CHUNK));
    }
  }
}
