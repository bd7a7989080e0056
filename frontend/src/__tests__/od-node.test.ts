import { describe, expect, it } from "vitest";
import { forNode, type Dictionary } from "../lib/od";

describe("a dictionary as one node sees it", () => {
  it("resolves $NODEID defaults and configured values for the node, leaving the others", () => {
    const variable = (subindex: number, extra: Record<string, unknown>) =>
      ({ subindex, name: `s${subindex}`, default: 5, configured: null, ...extra }) as never;
    const dictionary = {
      device: "x",
      objects: [
        {
          index: 0x1014,
          kind: "VAR",
          subs: [
            variable(0, { default: "$NODEID+0x80", default_node_offset: 0x80 }),
            variable(1, { configured: "$NODEID+0x200", configured_node_offset: 0x200 }),
          ],
        },
      ],
    } as unknown as Dictionary;
    const [first, second] = forNode(dictionary, 3).objects[0].subs;
    expect(first.default).toBe(0x83);
    expect(second.default).toBe(5);
    expect(second.configured).toBe(0x203);
    expect(dictionary.objects[0].subs[0].default).toBe("$NODEID+0x80");
  });
});
