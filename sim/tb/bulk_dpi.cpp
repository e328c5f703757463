// DPI side of the bulk wrapper's I/O on Verilator (sim/tb/bulk.py, io "dpi"; the wrapper
// is built with +define+BUMPRTL_BULK_DPI). The same files as the wrapper's $fread/$fwrite
// path, byte for byte: bulk_in.bin holds the stimulus words as ceil(IW/8) big-endian bytes
// each (what $fread reads into a memory), bulk_out.bin gets every output word as 32-bit
// little-endian limbs, least significant first (what $fwrite("%u") writes). Read and
// written in one piece per chunk; a word crosses the DPI boundary as a memcpy of its limbs
// instead of $fread's byte-by-byte parse and $fwrite's format string. One wrapper per
// simulator process (the state is this file's).
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "svdpi.h"

static std::vector<uint32_t> in_words;  // count words of in_limbs limbs each
static std::vector<uint32_t> out_words;
static int in_limbs = 0, out_limbs = 0;
static FILE* out_fp = nullptr;

// Reads `count` stimulus words of `iw` bits from `in_path`, opens `out_path` for the
// outputs (`ow` bits each). Returns the number of words read.
extern "C" int bulk_dpi_open(const char* in_path, int count, int iw, const char* out_path,
                             int ow) {
    in_limbs = (iw + 31) / 32;
    out_limbs = (ow + 31) / 32;
    const size_t nbytes = (iw + 7) / 8;
    std::vector<uint8_t> raw(size_t(count) * nbytes);
    size_t got = 0;
    if (FILE* f = std::fopen(in_path, "rb")) {
        got = std::fread(raw.data(), nbytes, count, f);
        std::fclose(f);
    }
    in_words.assign(size_t(count) * in_limbs, 0);
    for (size_t i = 0; i < got; i++) {
        const uint8_t* p = &raw[i * nbytes];
        uint32_t* w = &in_words[i * in_limbs];
        for (size_t b = 0; b < nbytes; b++) {
            const size_t j = nbytes - 1 - b;  // byte index from the least significant
            w[j / 4] |= uint32_t(p[b]) << (8 * (j % 4));
        }
    }
    out_words.clear();
    out_words.reserve(size_t(count) * out_limbs);
    if (out_fp) std::fclose(out_fp);
    out_fp = std::fopen(out_path, "wb");
    return int(got);
}

extern "C" void bulk_dpi_get(int index, svBitVecVal* word) {
    std::memcpy(word, &in_words[size_t(index) * in_limbs], 4 * size_t(in_limbs));
}

extern "C" void bulk_dpi_put(const svBitVecVal* word) {
    out_words.insert(out_words.end(), word, word + out_limbs);
}

extern "C" void bulk_dpi_close() {
    if (!out_fp) return;
    std::fwrite(out_words.data(), 4, out_words.size(), out_fp);
    std::fclose(out_fp);
    out_fp = nullptr;
}
