#pragma once
// Decodes a project's photos in the background while the GL passes run, so that the sample
// gathering finds them decoded: worker threads fill the PhotoCache in raster order, up
// to its memory budget. Errors are kept and raised, naming the photo, when the caller asks.
#include <atomic>
#include <cstddef>
#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "inputs/camera.h"  // Raster
#include "inputs/photo.h"

namespace vbrdf {

struct PhotoRequest {
  std::string path;
  int width = 0, height = 0;  // expected size (0 = not checked)
};

class PhotoPrefetch {
public:
  // Starts `threads` workers (0: one per hardware thread, at most 4) decoding `requests` in order
  // into `cache`; a worker stops taking photos once the next one would not fit in the cache's
  // budget (the gathering then decodes the rest on demand, as without prefetch). `cache` must
  // outlive this object.
  PhotoPrefetch(PhotoCache &cache, std::vector<PhotoRequest> requests, unsigned threads = 0);
  // Stops taking new photos and waits for the workers (never throws).
  ~PhotoPrefetch();
  PhotoPrefetch(const PhotoPrefetch &) = delete;
  PhotoPrefetch &operator=(const PhotoPrefetch &) = delete;

  // Waits for the workers and rethrows the error of the first photo (in request order) that
  // failed to decode, as PhotoCache::get threw it.
  void finish();

private:
  void work();
  void join();

  PhotoCache &cache_;
  std::vector<PhotoRequest> requests_;
  std::vector<std::exception_ptr> errors_;  // per request
  std::atomic<size_t> next_{0};
  std::atomic<bool> stop_{false};
  std::vector<std::thread> workers_;
};

// Decodes the first raster's photo now, in the caller's thread (so that a photo that cannot be
// decoded, or has the wrong size, usually fails before any long pass), and starts decoding the
// others in the background. Throws what PhotoCache::get throws for the first photo.
std::unique_ptr<PhotoPrefetch> start_photo_prefetch(PhotoCache &cache, const std::vector<Raster> &rasters);

} // namespace vbrdf
