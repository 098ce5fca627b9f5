// formats::write_lightmap_exr: OpenEXR's scanline ZIP format written through OpenEXRCore with the
// chunks deflated by libdeflate (exr_zip_chunks.h), on worker threads, stored in file order. A file
// of its own so that the loader, which only reads pages, links neither the writer nor libdeflate.
#include <openexr.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "exitance/formats/lightmap_exr.h"
#include "exr_zip_chunks.h"

namespace exitance::formats {

namespace {

// The chunks' deflate level: libdeflate level 4 costs about zlib level 1's CPU x 0.6 for files 2 %
// smaller than zlib level 1 gave (bench_exr_compression, bench/results/host-stages.md).
constexpr int kDeflateLevel = 4;

// OpenEXRCore reports errors through a callback on the thread that caused them.
thread_local std::string core_error;
void keep_core_error(exr_const_context_t, exr_result_t code, const char* message) {
  core_error = std::string(exr_get_error_code_as_string(code)) + ": " + (message ? message : "");
}

void check_core(exr_result_t result, const char* what) {
  if (result != EXR_ERR_SUCCESS)
    throw std::runtime_error(std::string(what) + ": " + (core_error.empty() ? exr_get_default_error_message(result) : core_error));
}

// A file left unfinished (an error on the way, or in finish() itself) is closed and removed: no
// partial page stays.
struct CoreWriteContext {
  exr_context_t context = nullptr;
  std::string path;
  bool finished = false;
  void finish() {
    check_core(exr_finish(&context), "finish");
    finished = true;
  }
  ~CoreWriteContext() {
    if (finished) return;
    if (context) exr_finish(&context);
    std::error_code ignored;
    if (!path.empty()) std::filesystem::remove(path, ignored);
  }
};

}  // namespace

// Scanline ZIP chunks compressed on `threads` workers (formats/src/exr_zip_chunks.h) and handed to
// OpenEXRCore in file order: the bytes are the same for any thread count.
void write_lightmap_exr(const std::string& path, const LightmapImage& image, int threads) {
  try {
    if (image.width <= 0 || image.height <= 0) throw std::runtime_error("empty image");
    const size_t width = size_t(image.width), pixels = width * size_t(image.height);
    for (const auto& [name, data] : image.channels)
      if (data.size() != pixels) throw std::runtime_error("channel " + name + " has the wrong size");
    core_error.clear();
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = keep_core_error;
    CoreWriteContext file;
    check_core(exr_start_write(&file.context, path.c_str(), EXR_WRITE_FILE_DIRECTLY, &init), "open");
    file.path = path;
    int part = 0;
    check_core(exr_add_part(file.context, nullptr, EXR_STORAGE_SCANLINE, &part), "part");
    check_core(exr_initialize_required_attr_simple(file.context, part, image.width, image.height, EXR_COMPRESSION_ZIP),
               "header");
    // std::map orders the channels by strcmp, the order OpenEXR keeps them in and stores each
    // scanline's channels in.
    std::vector<const float*> channels;
    for (const auto& [name, data] : image.channels) {
      check_core(exr_add_channel(file.context, part, name.c_str(), EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1),
                 "channel");
      channels.push_back(data.data());
    }
    check_core(exr_attr_set_string(file.context, part, "generator", "exitance"), "generator");
    check_core(exr_write_header(file.context), "header");

    const int chunk_count = (image.height + kExrZipScanlines - 1) / kExrZipScanlines;
    const size_t row_bytes = width * sizeof(float) * channels.size();
    auto encode_chunk = [&](int chunk, ExrZipChunkEncoder& encoder, std::vector<uint8_t>& raw, std::vector<uint8_t>& out) {
      const int y0 = chunk * kExrZipScanlines, rows = std::min(kExrZipScanlines, image.height - y0);
      raw.resize(row_bytes * size_t(rows));
      uint8_t* at = raw.data();
      for (int y = y0; y < y0 + rows; ++y)
        for (const float* channel : channels) {
          std::memcpy(at, channel + size_t(y) * width, width * sizeof(float));
          at += width * sizeof(float);
        }
      encoder.encode(raw.data(), raw.size(), out);
    };
    auto write_chunk = [&](int chunk, const std::vector<uint8_t>& bytes) {
      check_core(exr_write_scanline_chunk(file.context, part, chunk * kExrZipScanlines, bytes.data(), bytes.size()),
                 "chunk");
    };

    const int workers = std::min(chunk_count, threads < 0 ? lightmap_exr_threads() : threads);
    if (workers <= 1) {
      ExrZipChunkEncoder encoder(kDeflateLevel);
      std::vector<uint8_t> raw, out;
      for (int chunk = 0; chunk < chunk_count; ++chunk) {
        encode_chunk(chunk, encoder, raw, out);
        write_chunk(chunk, out);
      }
    } else {
      // Workers take chunks in order and may run at most `window` chunks ahead of the writer (this
      // thread), which stores each as soon as it and every chunk before it are done.
      const int window = 4 * workers;
      std::vector<std::vector<uint8_t>> done(static_cast<size_t>(chunk_count));
      std::vector<char> ready(size_t(chunk_count), char(0));
      std::mutex mutex;
      std::condition_variable changed;
      int next = 0, written = 0;
      bool failed = false;
      std::exception_ptr worker_error;
      auto work = [&] {
        try {
          ExrZipChunkEncoder encoder(kDeflateLevel);
          std::vector<uint8_t> raw;
          for (;;) {
            int chunk;
            {
              std::unique_lock lock(mutex);
              changed.wait(lock, [&] { return failed || next >= chunk_count || next < written + window; });
              if (failed || next >= chunk_count) return;
              chunk = next++;
            }
            std::vector<uint8_t> out;
            encode_chunk(chunk, encoder, raw, out);
            std::lock_guard lock(mutex);
            done[size_t(chunk)] = std::move(out);
            ready[size_t(chunk)] = 1;
            changed.notify_all();
          }
        } catch (...) {
          std::lock_guard lock(mutex);
          if (!worker_error) worker_error = std::current_exception();
          failed = true;
          changed.notify_all();
        }
      };
      std::vector<std::thread> pool;
      for (int w = 0; w < workers; ++w) pool.emplace_back(work);
      std::exception_ptr writer_error;
      try {
        while (written < chunk_count) {
          std::vector<uint8_t> bytes;
          {
            std::unique_lock lock(mutex);
            changed.wait(lock, [&] { return failed || ready[size_t(written)] != 0; });
            if (failed) break;
            bytes = std::move(done[size_t(written)]);
          }
          write_chunk(written, bytes);
          std::lock_guard lock(mutex);
          ++written;
          changed.notify_all();
        }
      } catch (...) {
        writer_error = std::current_exception();
        std::lock_guard lock(mutex);
        failed = true;
        changed.notify_all();
      }
      for (std::thread& t : pool) t.join();
      if (writer_error) std::rethrow_exception(writer_error);
      if (worker_error) std::rethrow_exception(worker_error);
    }
    file.finish();
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot write " + path + ": " + e.what());
  }
}

}  // namespace exitance::formats
