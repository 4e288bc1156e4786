// `node check.mjs FILE.ktx2...`: reads each file with ktx-parse's read() (the parser of three.js's
// KTX2Loader), inflates zstd levels (supercompressionScheme 2) with fzstd, and prints one JSON
// line per file: the header fields and the SHA-256 of each level's data, level 0 first. A file
// that fails to parse or inflate prints why and ends the run with exit status 1.
import { createHash } from "node:crypto";
import { readFileSync } from "node:fs";
import { basename } from "node:path";
import { decompress } from "fzstd";
import { read } from "ktx-parse";

const ZSTD = 2; // KTX 2.0 supercompressionScheme, Zstandard

function check(path) {
  const c = read(new Uint8Array(readFileSync(path)));
  const level_sha256 = c.levels.map(({ levelData, uncompressedByteLength }, i) => {
    let data = levelData;
    if (c.supercompressionScheme === ZSTD) {
      data = decompress(levelData);
      // The level index promises the inflated size; a short or long frame is a broken file.
      if (data.length !== uncompressedByteLength) {
        throw new Error(`level ${i}: ${data.length} bytes inflated, uncompressedByteLength ${uncompressedByteLength}`);
      }
    } else if (c.supercompressionScheme !== 0) {
      throw new Error(`supercompressionScheme ${c.supercompressionScheme} is not none or zstd`);
    }
    return createHash("sha256").update(data).digest("hex");
  });
  return {
    file: basename(path),
    vkFormat: c.vkFormat,
    width: c.pixelWidth,
    height: c.pixelHeight,
    depth: c.pixelDepth,
    layers: c.layerCount,
    faces: c.faceCount,
    levels: c.levelCount,
    supercompression: c.supercompressionScheme,
    level_sha256,
  };
}

let status = 0;
for (const path of process.argv.slice(2)) {
  try {
    console.log(JSON.stringify(check(path)));
  } catch (e) {
    console.error(`ktx-parse check: ${path}: ${e.message}`);
    status = 1;
  }
}
process.exitCode = status;
