/* capi_golden.c: the C API of needle-haptics against the golden vectors.
 *
 *   capi_golden <golden-f32.csv> [<golden-stiffness-f32.csv> [<golden-fixed.csv> <golden-stiffness-fixed.csv>]]
 *
 * 1. needle_wrench() on every golden row: status and the six wrench components bit
 *    for bit (NaN matches NaN).
 * 2. The control loop: for in-domain rows, needle_loop_tick() must command exactly the
 *    duties and direction pins of the documented linear map applied to the golden
 *    forces; then stale ticks ramp the command to zero and disable the output.
 * 3. Host-link commands: PING, LIMIT, and refused frames that change nothing.
 * 4. With the second file: needle_wrench_and_stiffness() on every row: status and the
 *    18 rates bit for bit, and the wrench the bits of needle_wrench().
 * 5. With the third and fourth files (same poses, row by row): needle_fixed_wrench() and
 *    needle_fixed_wrench_and_stiffness() on every row: status, the six wrench integers
 *    and the 18 rates exactly, and both calls' wrench and status the same.
 *
 * Prints "capi-golden rows=N wrench_mismatches=M loop_checks=K loop_failures=F command_failures=C"
 * (and with the second file "capi-golden-stiffness rows=N mismatches=M", with the third
 * and fourth "capi-golden-fixed rows=N mismatches=M")
 * and exits 0 only when every check passed. Compile with -ffp-contract=off.
 * Builds with host gcc and with arm-none-eabi-gcc (newlib, semihosting file I/O).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "needle.h"

static float f32(uint32_t bits) {
  float f;
  memcpy(&f, &bits, sizeof f);
  return f;
}

static uint32_t bits_of(float f) {
  uint32_t b;
  memcpy(&b, &f, sizeof b);
  return b;
}

static int same(float want, float got) {
  if (isnan(want)) return isnan(got);
  return bits_of(want) == bits_of(got);
}

static const float GAINS[3][3] = {{20.0f, 0.0f, 0.0f}, {0.0f, -10.0f, 0.0f}, {0.0f, 0.0f, 20.0f}};
static const bool INVERTED[3] = {false, false, true};
static const uint16_t MAX_DUTY[3] = {1000, 4095, 255};

/* The documented map of one channel: c = (g0*fx + g1*fy) + g2*fz. */
static float channel_c(const float g[3], const float f[3]) { return (g[0] * f[0] + g[1] * f[1]) + g[2] * f[2]; }

static uint16_t duty_of(float c, uint16_t max) {
  float a = c < 0.0f ? -c : c;
  if (a > 1.0f) a = 1.0f;
  return (uint16_t)(a * (float)max + 0.5f);
}

static int check_outputs(const needle_tick_t *t, const float f[3], bool enable, int line) {
  int bad = 0;
  for (int i = 0; i < 3; i++) {
    float c = channel_c(GAINS[i], f);
    uint16_t d = duty_of(c, MAX_DUTY[i]);
    bool dir = (c >= 0.0f) != INVERTED[i];
    if (t->duty[i] != d || t->direction_high[i] != dir) {
      printf("line %d channel %d: duty %u dir %d, want %u %d\n", line, i, t->duty[i], t->direction_high[i], d, dir);
      bad++;
    }
  }
  if (t->enable != enable) {
    printf("line %d: enable %d, want %d\n", line, t->enable, enable);
    bad++;
  }
  return bad;
}

/* Section 4: every row of golden-stiffness-f32.csv through needle_wrench_and_stiffness;
 * returns the number of mismatching rows, or -1 when the file is unreadable or malformed. */
static int check_stiffness(const char *path, int *rows_out) {
  FILE *fp = fopen(path, "r");
  if (!fp) {
    printf("cannot open %s\n", path);
    return -1;
  }
  char line[1024];
  int rows = 0, mismatches = 0, lineno = 1;
  if (!fgets(line, sizeof line, fp)) {
    fclose(fp);
    return -1;
  }
  while (fgets(line, sizeof line, fp)) {
    lineno++;
    unsigned int v[24];
    char *at = line;
    for (int i = 0; i < 24; i++) {
      char *end;
      v[i] = (unsigned int)strtoul(at, &end, 16); /* "0x..." fields, status included */
      if (end == at || (i < 23 && *end != ',')) {
        printf("golden-stiffness line %d: malformed\n", lineno);
        fclose(fp);
        return -1;
      }
      at = end + 1;
    }
    needle_pose_t p = {f32(v[0]), f32(v[1]), f32(v[2]), f32(v[3]), f32(v[4])};
    needle_wrench_t w, plain;
    needle_stiffness_t k;
    uint8_t status = needle_wrench_and_stiffness(&p, &w, &k);
    uint8_t plain_status = needle_wrench(&p, &plain);
    int bad = status != v[5] || status != plain_status;
    for (int c = 0; c < 6; c++) {
      bad |= !same(f32(v[6 + c]), k.by_depth[c]);
      bad |= !same(f32(v[12 + c]), k.by_x[c]);
      bad |= !same(f32(v[18 + c]), k.by_z[c]);
    }
    bad |= memcmp(&w, &plain, sizeof w) != 0;
    if (bad) {
      if (mismatches < 10) printf("golden-stiffness line %d differs\n", lineno);
      mismatches++;
    }
    rows++;
  }
  fclose(fp);
  *rows_out = rows;
  return mismatches;
}

/* Parses `n` comma-separated integers (decimal, or 0x-prefixed hex for the status) from
 * `line`; returns 0 on success. */
static int parse_ints(const char *line, long *v, int n) {
  const char *at = line;
  for (int i = 0; i < n; i++) {
    char *end;
    v[i] = strtol(at, &end, 0);
    if (end == at || (i < n - 1 && *end != ',')) return -1;
    at = end + 1;
  }
  return 0;
}

/* Section 5: golden-fixed.csv and golden-stiffness-fixed.csv row by row through
 * needle_fixed_wrench and needle_fixed_wrench_and_stiffness; returns the number of
 * mismatching rows, or -1 when a file is unreadable or malformed. */
static int check_fixed(const char *wrench_path, const char *stiffness_path, int *rows_out) {
  FILE *fw = fopen(wrench_path, "r");
  FILE *fs = fopen(stiffness_path, "r");
  int result = -1, rows = 0, mismatches = 0, lineno = 1;
  char lw[512], ls[1024];
  if (!fw || !fs) {
    printf("cannot open %s or %s\n", wrench_path, stiffness_path);
    goto done;
  }
  if (!fgets(lw, sizeof lw, fw) || !fgets(ls, sizeof ls, fs)) goto done;
  for (;;) {
    char *gw = fgets(lw, sizeof lw, fw);
    char *gs = fgets(ls, sizeof ls, fs);
    if (!gw && !gs) break;
    lineno++;
    long w[12], k[24];
    if (!gw || !gs || parse_ints(lw, w, 12) || parse_ints(ls, k, 24)) {
      printf("golden-fixed line %d: malformed or the files differ in length\n", lineno);
      goto done;
    }
    if (memcmp(w, k, 5 * sizeof w[0]) != 0) {
      printf("golden-fixed line %d: the two files hold other poses\n", lineno);
      goto done;
    }
    needle_fixed_pose_t p = {(int32_t)w[0], (int32_t)w[1], (int32_t)w[2], (int32_t)w[3], (int32_t)w[4]};
    needle_fixed_wrench_t plain, both;
    needle_fixed_stiffness_t r;
    uint8_t plain_status = needle_fixed_wrench(&p, &plain);
    uint8_t status = needle_fixed_wrench_and_stiffness(&p, &both, &r);
    int32_t pw[6] = {plain.fx_un, plain.fy_un, plain.fz_un, plain.mx_unmm, plain.my_unmm, plain.mz_unmm};
    int bad = plain_status != w[5] || status != k[5] || memcmp(&plain, &both, sizeof plain) != 0;
    for (int c = 0; c < 6; c++) {
      bad |= pw[c] != w[6 + c];
      bad |= r.by_depth[c] != k[6 + c] || r.by_x[c] != k[12 + c] || r.by_z[c] != k[18 + c];
    }
    if (bad) {
      if (mismatches < 10) printf("golden-fixed line %d differs\n", lineno);
      mismatches++;
    }
    rows++;
  }
  *rows_out = rows;
  result = mismatches;
done:
  if (fw) fclose(fw);
  if (fs) fclose(fs);
  return result;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    printf("usage: capi_golden <golden-f32.csv>\n");
    return 2;
  }
  FILE *fp = fopen(argv[1], "r");
  if (!fp) {
    printf("cannot open %s\n", argv[1]);
    return 2;
  }
  needle_model_info_t info;
  if (needle_model_info(&info) != NEEDLE_OK || !info.fitted) {
    printf("no fitted model in the library\n");
    return 2;
  }

  needle_loop_config_t cfg;
  memset(&cfg, 0, sizeof cfg);
  for (int i = 0; i < 3; i++) {
    for (int k = 0; k < 3; k++) cfg.channels[i].gains_per_n[k] = GAINS[i][k];
    cfg.channels[i].direction_inverted = INVERTED[i];
  }
  cfg.force_limit_n = 10.0f;
  cfg.force_limit_max_n = 20.0f;
  cfg.over_limit = NEEDLE_OVER_LIMIT_SATURATE;
  cfg.ramp_step_n = 0.01f;
  needle_loop_t loop;
  if (needle_loop_init(&loop, &cfg) != NEEDLE_OK) {
    printf("needle_loop_init failed\n");
    return 2;
  }

  char line[512];
  int rows = 0, mismatches = 0, loop_checks = 0, loop_failures = 0, lineno = 1;
  float last_f[3] = {0, 0, 0};
  needle_pose_t last_pose;
  int have_last = 0;
  if (!fgets(line, sizeof line, fp)) return 2; /* header */
  while (fgets(line, sizeof line, fp)) {
    lineno++;
    unsigned int v[12];
    if (sscanf(line, "0x%x,0x%x,0x%x,0x%x,0x%x,0x%x,0x%x,0x%x,0x%x,0x%x,0x%x,0x%x", &v[0], &v[1], &v[2], &v[3],
               &v[4], &v[5], &v[6], &v[7], &v[8], &v[9], &v[10], &v[11]) != 12) {
      printf("golden line %d: malformed\n", lineno);
      return 2;
    }
    needle_pose_t p = {f32(v[0]), f32(v[1]), f32(v[2]), f32(v[3]), f32(v[4])};
    needle_wrench_t w;
    uint8_t status = needle_wrench(&p, &w);
    float got[6] = {w.fx_n, w.fy_n, w.fz_n, w.mx_nmm, w.my_nmm, w.mz_nmm};
    int bad = status != v[5];
    for (int c = 0; c < 6; c++) bad |= !same(f32(v[6 + c]), got[c]);
    if (bad) {
      if (mismatches < 10) printf("golden line %d differs (status 0x%02x want 0x%02x)\n", lineno, status, v[5]);
      if (mismatches < 10 && status & NEEDLE_STATUS_ERROR) printf("  status has %s\n", needle_status_name(NEEDLE_STATUS_ERROR));
      mismatches++;
    }
    rows++;
    /* Loop: every 50th in-domain row, one fresh tick. */
    if (v[5] == 0 && rows % 50 == 0) {
      needle_tick_t t;
      float f[3] = {f32(v[6]), f32(v[7]), f32(v[8])};
      if (needle_loop_tick(&loop, &p, NEEDLE_POSE_FRESH, MAX_DUTY, &t) != NEEDLE_OK) return 2;
      loop_checks++;
      int b = check_outputs(&t, f, true, lineno);
      for (int c = 0; c < 3; c++) b += bits_of(t.force_cmd_n[c]) != bits_of(f[c]);
      b += t.flags != 0 && t.flags != NEEDLE_LOOP_DUTY_CLIPPED;
      loop_failures += b != 0;
      memcpy(last_f, f, sizeof f);
      last_pose = p;
      have_last = 1;
    }
  }
  fclose(fp);
  if (!have_last) {
    printf("no in-domain golden rows\n");
    return 2;
  }

  /* Stale ticks: each component towards zero by at most 0.01 N a tick, then disabled. */
  float cmd[3];
  memcpy(cmd, last_f, sizeof cmd);
  for (int k = 0; k < 200; k++) {
    for (int c = 0; c < 3; c++) cmd[c] = cmd[c] > 0.01f ? cmd[c] - 0.01f : (cmd[c] < -0.01f ? cmd[c] + 0.01f : 0.0f);
    needle_tick_t t;
    if (needle_loop_tick(&loop, NULL, NEEDLE_POSE_STALE, MAX_DUTY, &t) != NEEDLE_OK) return 2;
    bool zero = cmd[0] == 0.0f && cmd[1] == 0.0f && cmd[2] == 0.0f;
    loop_checks++;
    int b = check_outputs(&t, cmd, !zero, -k);
    for (int c = 0; c < 3; c++) b += bits_of(t.force_cmd_n[c]) != bits_of(cmd[c]);
    b += (t.flags & (NEEDLE_LOOP_POSE_STALE | NEEDLE_LOOP_RAMPING)) != (NEEDLE_LOOP_POSE_STALE | NEEDLE_LOOP_RAMPING);
    b += zero != ((t.flags & NEEDLE_LOOP_DISABLED) != 0); /* once at zero */
    loop_failures += b != 0;
    if (zero) break;
  }
  /* Fresh again: follows the model at once. */
  {
    needle_tick_t t;
    if (needle_loop_tick(&loop, &last_pose, NEEDLE_POSE_FRESH, MAX_DUTY, &t) != NEEDLE_OK) return 2;
    loop_checks++;
    loop_failures += check_outputs(&t, last_f, true, 0) != 0;
  }

  /* Commands. */
  int command_failures = 0;
  char reply[128];
  needle_loop_t before = loop;
  struct {
    const char *frame;
    const char *want;
  } cases[] = {
      {"PING", "OK PONG\n"},
      {"LIMIT 2500", "OK LIMIT limit_mn=2500\n"},
      {"LIMIT 0", "ERR RANGE limit_mn must be 1..=20000\n"},
      {"LIMIT x", "ERR MALFORMED a number is 1 to 9 decimal digits\n"},
      {"FLY", "ERR UNKNOWN no such command\n"},
  };
  for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    size_t n = needle_loop_command(&loop, (const uint8_t *)cases[i].frame, strlen(cases[i].frame), 0, (uint8_t *)reply,
                                   sizeof reply);
    if (n != strlen(cases[i].want) || strcmp(reply, cases[i].want) != 0) {
      printf("command %s: reply %s", cases[i].frame, reply);
      command_failures++;
    }
    if (i == 1) before = loop;
    if (i >= 2 && memcmp(&before, &loop, sizeof loop) != 0) {
      printf("command %s changed the loop\n", cases[i].frame);
      command_failures++;
    }
  }
  if (needle_loop_set_force_limit_n(&loop, 30.0f) != NEEDLE_E_CONFIG) command_failures++;
  if (needle_loop_tick(NULL, NULL, NEEDLE_POSE_MISSING, MAX_DUTY, NULL) != NEEDLE_E_NULL) command_failures++;
  /* The names C users print: error codes, status bits, loop flags. */
  if (strcmp(needle_strerror(NEEDLE_E_NULL), "NULL pointer argument") != 0) command_failures++;
  if (strcmp(needle_status_name(NEEDLE_STATUS_SAT_DEPTH), "SAT_DEPTH") != 0) command_failures++;
  if (strcmp(needle_status_name(NEEDLE_STATUS_FE_UNSOLVED), "FE_UNSOLVED") != 0) command_failures++;
  if (needle_status_name(NEEDLE_STATUS_SAT_X | NEEDLE_STATUS_SAT_Z) != NULL) command_failures++;
  if (strcmp(needle_loop_flag_name(NEEDLE_LOOP_RAMPING), "RAMPING") != 0) command_failures++;
  {
    char text[8];
    size_t n = needle_status_str(NEEDLE_STATUS_SAT_X | NEEDLE_STATUS_SAT_DEPTH, text, sizeof text);
    if (n != strlen("SAT_X | SAT_DEPTH") || strcmp(text, "SAT_X |") != 0) command_failures++; /* truncated */
  }

  printf("capi-golden set=%s rows=%d wrench_mismatches=%d loop_checks=%d loop_failures=%d command_failures=%d\n",
         (const char *)info.set, rows, mismatches, loop_checks, loop_failures, command_failures);
  int stiffness_failed = 0;
  if (argc > 2) {
    int stiffness_rows = 0;
    int stiffness_mismatches = check_stiffness(argv[2], &stiffness_rows);
    printf("capi-golden-stiffness rows=%d mismatches=%d\n", stiffness_rows, stiffness_mismatches);
    stiffness_failed = stiffness_mismatches != 0 || stiffness_rows < 2000;
  }
  int fixed_failed = 0;
  if (argc > 4) {
    int fixed_rows = 0;
    int fixed_mismatches = check_fixed(argv[3], argv[4], &fixed_rows);
    printf("capi-golden-fixed rows=%d mismatches=%d\n", fixed_rows, fixed_mismatches);
    fixed_failed = fixed_mismatches != 0 || fixed_rows < 2000;
  }
  return (mismatches || loop_failures || command_failures || rows < 2000 || stiffness_failed || fixed_failed) ? 1 : 0;
}
