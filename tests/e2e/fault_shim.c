/* LD_PRELOAD shim for the fault cases of run_e2e.py: makes a run die or dawdle at a
 * chosen point of writing an output, without any hook in the product.
 *   VBRDF_FAULT=kill_mid_write  SIGKILL once 64 KiB went through fwrite into a temporary
 *                               (name containing ".tmp") of a file whose name contains VBRDF_FAULT_TARGET
 *   VBRDF_FAULT=kill_at_rename  SIGKILL when such a temporary is about to be renamed into place
 *   VBRDF_FAULT=slow_rename     sleep VBRDF_FAULT_SLEEP seconds (default 3) before that rename
 * Other processes (xvfb-run, Xvfb) and other files are not affected. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int targeted(const char *path) {
  const char *target = getenv("VBRDF_FAULT_TARGET");
  return path && target && strstr(path, target) && strstr(path, ".tmp");
}

static int fault_is(const char *what) {
  const char *f = getenv("VBRDF_FAULT");
  return f && strcmp(f, what) == 0;
}

int rename(const char *from, const char *to) {
  static int (*real)(const char *, const char *);
  if (!real) real = (int (*)(const char *, const char *))dlsym(RTLD_NEXT, "rename");
  if (targeted(from)) {
    if (fault_is("kill_at_rename")) raise(SIGKILL);
    if (fault_is("slow_rename")) {
      const char *s = getenv("VBRDF_FAULT_SLEEP");
      sleep(s ? (unsigned)atoi(s) : 3u);
    }
  }
  return real(from, to);
}

static FILE *last;  /* the stream whose verdict is cached (forgotten when it is closed) */

int fclose(FILE *stream) {
  static int (*real)(FILE *);
  if (!real) real = (int (*)(FILE *))dlsym(RTLD_NEXT, "fclose");
  if (stream == last) last = NULL;
  return real(stream);
}

size_t fwrite(const void *ptr, size_t size, size_t n, FILE *stream) {
  static size_t (*real)(const void *, size_t, size_t, FILE *);
  static int last_targeted;
  static size_t written;
  if (!real) real = (size_t(*)(const void *, size_t, size_t, FILE *))dlsym(RTLD_NEXT, "fwrite");
  if (fault_is("kill_mid_write")) {
    if (stream != last) {
      char link[64], path[4096];
      snprintf(link, sizeof link, "/proc/self/fd/%d", fileno(stream));
      const ssize_t len = readlink(link, path, sizeof path - 1);
      path[len > 0 ? len : 0] = '\0';
      last = stream;
      last_targeted = targeted(path);
    }
    if (last_targeted) {
      written += size * n;
      if (written >= 65536) {
        fflush(stream);
        raise(SIGKILL);
      }
    }
  }
  return real(ptr, size, n, stream);
}
