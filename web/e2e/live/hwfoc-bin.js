// Where the tests find the hwfoc binary.
import { existsSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

const repo = fileURLToPath(new URL('../../../', import.meta.url));

/** The hwfoc binary: $HWFOC (as web/e2e/harness.mjs), else the workspace's debug build; null if none. */
export function hwfocBin() {
  const bin = process.env.HWFOC ?? `${repo}target/debug/hwfoc`;
  return existsSync(bin) ? bin : null;
}
