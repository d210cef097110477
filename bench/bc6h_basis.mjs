// Issue 19: Basis Universal's BC6H for bench/bc6h_vs_basis.sh. Encodes each EXR as UASTC HDR 4x4
// (the ktx2-encoder npm package's basis_encoder.wasm, Basis Universal 2.x, single-threaded) and
// transcodes it to BC6H with the same module's transcoder; writes the raw blocks (row-major,
// 16 bytes each) to OUTDIR/NAME.bc6h and prints one line per image with the two times.
//
//   node bench/bc6h_basis.mjs BASIS_ENCODER_JS OUTDIR LEVEL IMAGE.exr...
import { readFileSync, writeFileSync } from "node:fs";
import { basename } from "node:path";
import { pathToFileURL } from "node:url";

const [modulePath, outDir, levelArg, ...images] = process.argv.slice(2);
const BASIS = (await import(pathToFileURL(modulePath).href)).default;
const m = await BASIS();
m.initializeBasis();
const level = Number(levelArg);
for (const path of images) {
  const exr = new Uint8Array(readFileSync(path));
  const enc = new m.BasisEncoder();
  enc.setCreateKTX2File(true);
  enc.setKTX2UASTCSupercompression(false);
  enc.setMipGen(false);
  enc.setFormatMode(m.basis_tex_format.cUASTC_HDR_4x4.value);
  enc.setUASTCHDRQualityLevel(level);
  if (enc.controlThreading) enc.controlThreading(false, 1);
  if (!enc.setSliceSourceImageHDR(0, exr, 0, 0, m.hdr_image_type.cHITEXRImage.value, true, 100))
    throw new Error(`${path}: setSliceSourceImageHDR failed`);
  const out = new Uint8Array(exr.length * 8 + (1 << 24));
  let t0 = process.hrtime.bigint();
  const n = enc.encode(out);
  const encodeS = Number(process.hrtime.bigint() - t0) / 1e9;
  enc.delete();
  if (!n) throw new Error(`${path}: encode failed`);
  const ktx2 = new m.KTX2File(out.slice(0, n));
  if (!ktx2.isValid()) throw new Error(`${path}: not a valid KTX2 file`);
  const w = ktx2.getWidth(), h = ktx2.getHeight();
  const fmt = m.transcoder_texture_format.cTFBC6H.value;
  const blocks = new Uint8Array(ktx2.getImageTranscodedSizeInBytes(0, 0, 0, fmt));
  t0 = process.hrtime.bigint();
  if (!ktx2.startTranscoding() || !ktx2.transcodeImage(blocks, 0, 0, 0, fmt, 0, -1, -1))
    throw new Error(`${path}: transcode to BC6H failed`);
  const transcodeS = Number(process.hrtime.bigint() - t0) / 1e9;
  ktx2.close();
  ktx2.delete();
  const name = basename(path).replace(/\.[^.]*$/, "");
  writeFileSync(`${outDir}/${name}.bc6h`, blocks);
  console.log(`${name} ${w}x${h} uastc_hdr_bytes ${n} encode_s ${encodeS.toFixed(3)} ` +
              `transcode_s ${transcodeS.toFixed(4)}`);
}
