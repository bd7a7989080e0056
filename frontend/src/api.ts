/** Typed access to the communication server's REST API (same origin). */

export interface Health {
  status: string;
  version: string;
}

export async function getJson<T>(path: string, fetchImpl: typeof fetch = fetch): Promise<T> {
  const response = await fetchImpl(path, { headers: { Accept: "application/json" } });
  if (!response.ok) {
    throw new Error(`${path}: HTTP ${response.status}`);
  }
  return (await response.json()) as T;
}

export function getHealth(fetchImpl: typeof fetch = fetch): Promise<Health> {
  return getJson<Health>("/api/health", fetchImpl);
}
