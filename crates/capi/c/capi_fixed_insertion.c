/* capi_fixed_insertion.c: the fixed-point insertion model through the C API.
 *
 *   capi_fixed_insertion <ticks.txt>
 *
 * <ticks.txt> holds one tick per line, "<stack> <path> <x> <z> <theta_x> <theta_z> <depth>",
 * each pose input a Q16.16 integer as the hex of its 32 bits (the golden insertion paths
 * of examples/common/insertion_paths.rs, for_each_tick_q16, written by
 * tests/c_insertion.rs). For every (stack, path), in file order:
 * needle_fixed_insertion_init(stack, 1000 us, 5000 us) and needle_fixed_insertion_step()
 * on each tick; prints "fixed stack=<s> path=<p> ticks=<n> punctures=<n> digest_hi=0x..
 * digest_lo=0x..", the digest FNV-1a over each tick's six wrench integers, status, phase
 * code, punctures and flags (examples/common/insertion_paths.rs, Digest::tick_fixed).
 *
 * The test compares every line with the library's own run. Exits 0 when every call
 * returned NEEDLE_OK and the refusals below hold.
 */
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

typedef struct {
  char stack[32];
  int path;
  needle_fixed_insertion_t ins;
  uint64_t digest;
  unsigned long ticks, punctures;
} run_t;

static int start(run_t *r, const char *stack, int path) {
  snprintf(r->stack, sizeof r->stack, "%s", stack);
  r->path = path;
  r->digest = 0xcbf29ce484222325ull;
  r->ticks = r->punctures = 0;
  return needle_fixed_insertion_init(&r->ins, stack, 1000u, 5000u) == NEEDLE_OK;
}

static void finish(const run_t *r) {
  printf("fixed stack=%s path=%d ticks=%lu punctures=%lu digest_hi=0x%08lx digest_lo=0x%08lx\n", r->stack, r->path, r->ticks,
         r->punctures, (unsigned long)(r->digest >> 32), (unsigned long)(r->digest & 0xffffffffu));
}

static int tick(run_t *r, const needle_fixed_pose_t *p) {
  needle_fixed_insertion_result_t e;
  if (needle_fixed_insertion_step(&r->ins, p, &e) != NEEDLE_OK) return 0;
  const int32_t w[6] = {e.wrench.fx_un, e.wrench.fy_un, e.wrench.fz_un, e.wrench.mx_unmm, e.wrench.my_unmm, e.wrench.mz_unmm};
  for (int i = 0; i < 6; i++) r->digest = fnv_word(r->digest, (uint32_t)w[i]);
  r->digest = fnv_word(r->digest, e.status);
  r->digest = fnv_word(r->digest, e.phase);
  r->digest = fnv_word(r->digest, e.punctures);
  r->digest = fnv_word(r->digest, e.flags);
  r->ticks++;
  r->punctures += e.punctures;
  return 1;
}

/* Refusals: an uninitialised state, a NULL pose, a zero period, an unknown stack, a
 * scale count other than the stack's. */
static int refusals(const char *stack) {
  needle_fixed_insertion_t s;
  memset(&s, 0, sizeof s);
  needle_fixed_pose_t p;
  memset(&p, 0, sizeof p);
  needle_fixed_insertion_result_t out;
  int32_t one = 65536;
  int ok = needle_fixed_insertion_step(&s, &p, &out) == NEEDLE_E_UNINIT;
  ok &= needle_fixed_insertion_init(&s, stack, 0u, 5000u) == NEEDLE_E_CONFIG && s.magic != NEEDLE_FIXED_INSERTION_MAGIC;
  ok &= needle_fixed_insertion_init(&s, "no-such-stack", 1000u, 5000u) == NEEDLE_E_ARG;
  ok &= needle_fixed_insertion_init(&s, stack, 1000u, 5000u) == NEEDLE_OK;
  ok &= needle_fixed_insertion_step(&s, NULL, &out) == NEEDLE_E_NULL;
  ok &= needle_fixed_insertion_set_scales(&s, &one, 99u) == NEEDLE_E_ARG;
  ok &= needle_fixed_insertion_reset(&s) == NEEDLE_OK;
  return ok;
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: capi_fixed_insertion <ticks.txt>\n");
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
  char stack[32], first[32] = "";
  int path;
  unsigned x, z, tx, tz, d;
  unsigned long line = 0;
  while (fscanf(f, "%31s %d %x %x %x %x %x", stack, &path, &x, &z, &tx, &tz, &d) == 7) {
    line++;
    if (!first[0]) snprintf(first, sizeof first, "%s", stack);
    if (!open || strcmp(stack, r->stack) != 0 || path != r->path) {
      if (open) finish(r);
      if (!start(r, stack, path)) {
        fprintf(stderr, "%s:%lu: cannot start stack %s\n", argv[1], line, stack);
        return 1;
      }
      open = 1;
    }
    needle_fixed_pose_t p = {(int32_t)x, (int32_t)z, (int32_t)tx, (int32_t)tz, (int32_t)d};
    if (!tick(r, &p)) {
      fprintf(stderr, "%s:%lu: a call failed\n", argv[1], line);
      failures++;
    }
  }
  if (open) finish(r);
  fclose(f);
  free(r);
  int refused = first[0] && refusals(first);
  printf("capi-fixed-insertion ticks_read=%lu failures=%d refusals=%s\n", line, failures, refused ? "ok" : "FAILED");
  return failures == 0 && refused && line > 0 ? 0 : 1;
}
