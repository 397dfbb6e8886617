/* capi_insertion.c: the insertion model through the C API, against the Rust library.
 *
 *   capi_insertion <ticks.txt>
 *
 * <ticks.txt> holds one tick per line, "<stack> <path> <x> <z> <theta_x> <theta_z> <depth>",
 * each pose input as the hex bits of an f32 (the golden insertion paths of
 * examples/common/insertion_paths.rs, written by tests/c_program.rs). For every
 * (stack, path), in file order:
 *
 * 1. needle_insertion_init(stack, 1 kHz, 5 ms) and needle_insertion_step() on each tick;
 *    prints "stack=<s> path=<p> ticks=<n> punctures=<n> digest_hi=0x.. digest_lo=0x..",
 *    the digest FNV-1a over each tick's six wrench bits, status, phase code,
 *    punctures and flags (examples/common/insertion_paths.rs, Digest::tick);
 * 2. a loop (needle_loop_init, then needle_loop_set_insertion with a fresh insertion of
 *    the stack) ticked on the same poses; prints "loop stack=<s> path=<p> digest_hi=0x..
 *    digest_lo=0x..", the digest over each tick's commanded force bits, flags and model
 *    status.
 *
 * The test compares every line with the library's own run. Exits 0 when every call
 * returned NEEDLE_OK and the refusals below hold. Compile with -ffp-contract=off.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "needle.h"

static uint64_t fnv_word(uint64_t h, uint32_t w) {
  for (int i = 0; i < 4; i++) {
    h ^= (uint64_t)((w >> (8 * i)) & 0xffu);
    h *= 0x00000100000001b3ull;
  }
  return h;
}

static uint32_t bits_of(float f) {
  uint32_t b;
  memcpy(&b, &f, sizeof b);
  return b;
}

static float f32_of(uint32_t b) {
  float f;
  memcpy(&f, &b, sizeof f);
  return f;
}

typedef struct {
  char stack[32];
  int path;
  needle_insertion_t ins;
  needle_loop_t loop;
  uint64_t digest, loop_digest;
  unsigned long ticks, punctures;
} run_t;

static const uint16_t MAX_DUTY[NEEDLE_CHANNELS] = {1000, 1000, 1000};

static int start(run_t *r, const char *stack, int path) {
  snprintf(r->stack, sizeof r->stack, "%s", stack);
  r->path = path;
  r->digest = r->loop_digest = 0xcbf29ce484222325ull;
  r->ticks = r->punctures = 0;
  needle_loop_config_t c;
  memset(&c, 0, sizeof c);
  for (int i = 0; i < NEEDLE_CHANNELS; i++) c.channels[i].gains_per_n[i] = 0.01f;
  c.force_limit_n = 100.0f;
  c.force_limit_max_n = 100.0f;
  c.over_limit = NEEDLE_OVER_LIMIT_SATURATE;
  c.ramp_step_n = 0.01f;
  needle_insertion_t fresh;
  if (needle_insertion_init(&r->ins, stack, 0.001f, 0.005f) != NEEDLE_OK) return 0;
  if (needle_insertion_init(&fresh, stack, 0.001f, 0.005f) != NEEDLE_OK) return 0;
  if (needle_loop_init(&r->loop, &c) != NEEDLE_OK) return 0;
  return needle_loop_set_insertion(&r->loop, &fresh) == NEEDLE_OK;
}

static void finish(const run_t *r) {
  printf("stack=%s path=%d ticks=%lu punctures=%lu digest_hi=0x%08lx digest_lo=0x%08lx\n", r->stack, r->path, r->ticks, r->punctures,
         (unsigned long)(r->digest >> 32), (unsigned long)(r->digest & 0xffffffffu));
  printf("loop stack=%s path=%d digest_hi=0x%08lx digest_lo=0x%08lx\n", r->stack, r->path, (unsigned long)(r->loop_digest >> 32),
         (unsigned long)(r->loop_digest & 0xffffffffu));
}

static int tick(run_t *r, const needle_pose_t *p) {
  needle_insertion_result_t e;
  if (needle_insertion_step(&r->ins, p, &e) != NEEDLE_OK) return 0;
  const float w[6] = {e.wrench.fx_n, e.wrench.fy_n, e.wrench.fz_n, e.wrench.mx_nmm, e.wrench.my_nmm, e.wrench.mz_nmm};
  for (int i = 0; i < 6; i++) r->digest = fnv_word(r->digest, bits_of(w[i]));
  r->digest = fnv_word(r->digest, e.status);
  r->digest = fnv_word(r->digest, e.phase);
  r->digest = fnv_word(r->digest, e.punctures);
  r->digest = fnv_word(r->digest, e.flags);
  r->ticks++;
  r->punctures += e.punctures;
  needle_tick_t t;
  if (needle_loop_tick(&r->loop, p, NEEDLE_POSE_FRESH, MAX_DUTY, &t) != NEEDLE_OK) return 0;
  for (int i = 0; i < 3; i++) r->loop_digest = fnv_word(r->loop_digest, bits_of(t.force_cmd_n[i]));
  r->loop_digest = fnv_word(r->loop_digest, t.flags);
  r->loop_digest = fnv_word(r->loop_digest, t.model_status);
  return 1;
}

/* Refusals: an uninitialised insertion, a NULL loop (NULL insertion goes back to the
 * block model); a loop whose ramp step is infinite (no ramp at all). */
static int refusals(void) {
  needle_loop_t l;
  needle_insertion_t none;
  memset(&l, 0, sizeof l);
  memset(&none, 0, sizeof none);
  needle_loop_config_t c;
  memset(&c, 0, sizeof c);
  c.force_limit_n = 1.0f;
  c.force_limit_max_n = 1.0f;
  c.ramp_step_n = 0.01f;
  c.ramp_step_n = INFINITY;
  int ok = needle_loop_init(&l, &c) == NEEDLE_E_CONFIG && l.magic != NEEDLE_LOOP_MAGIC;
  c.ramp_step_n = 0.01f;
  ok &= needle_loop_set_insertion(NULL, NULL) == NEEDLE_E_NULL;
  ok &= needle_loop_set_insertion(&l, NULL) == NEEDLE_E_UNINIT;
  ok &= needle_loop_init(&l, &c) == NEEDLE_OK;
  ok &= needle_loop_set_insertion(&l, &none) == NEEDLE_E_UNINIT;
  ok &= needle_loop_set_insertion(&l, NULL) == NEEDLE_OK;
  return ok;
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: capi_insertion <ticks.txt>\n");
    return 2;
  }
  FILE *f = fopen(argv[1], "r");
  if (!f) {
    perror(argv[1]);
    return 2;
  }
  run_t *r = calloc(1, sizeof *r);
  if (!r) return 2;
  int open = 0, failures = 0;
  char stack[32];
  int path;
  unsigned x, z, tx, tz, d;
  unsigned long line = 0;
  while (fscanf(f, "%31s %d %x %x %x %x %x", stack, &path, &x, &z, &tx, &tz, &d) == 7) {
    line++;
    if (!open || strcmp(stack, r->stack) != 0 || path != r->path) {
      if (open) finish(r);
      if (!start(r, stack, path)) {
        fprintf(stderr, "%s:%lu: cannot start stack %s\n", argv[1], line, stack);
        return 1;
      }
      open = 1;
    }
    needle_pose_t p = {f32_of(x), f32_of(z), f32_of(tx), f32_of(tz), f32_of(d)};
    if (!tick(r, &p)) {
      fprintf(stderr, "%s:%lu: a call failed\n", argv[1], line);
      failures++;
    }
  }
  if (open) finish(r);
  fclose(f);
  free(r);
  int refused = refusals();
  printf("capi-insertion ticks_read=%lu failures=%d refusals=%s\n", line, failures, refused ? "ok" : "FAILED");
  return failures == 0 && refused && line > 0 ? 0 : 1;
}
