/* harness.c: feeds the rows of a tidy CSV to an exported compensator (rlgtherm export --c) and
 * prints one line per row: the compensated bias (deg/h, 17 significant digits) and the state's
 * outside_range flag after the update. Each run starts with an init. Built by c_code.sh against
 * one export:
 *   cc -std=c99 -DPREFIX=rlg_comp -DPREFIX_UPPER=RLG_COMP -DHEADER='"rlg_comp.h"' -Idir harness.c dir/rlg_comp.c -lm
 * Usage: harness DATA.csv > values.txt (a summary on stderr). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include HEADER

#define PASTE2(a, b) a##b
#define PASTE(a, b) PASTE2(a, b)
#define STATE PASTE(PREFIX, _state)
#define INIT PASTE(PREFIX, _init)
#define UPDATE PASTE(PREFIX, _update)
#define REAL PASTE(PREFIX_UPPER, _REAL)
#define CHANNELS PASTE(PREFIX_UPPER, _CHANNELS)
#define CHANNEL_NAMES PASTE(PREFIX_UPPER, _CHANNEL_NAMES)

#define MAX_LINE 4096
#define MAX_FIELDS 64

/* Splits a CSV line in place at commas (the tidy CSV quotes nothing); returns the field count. */
static int Split(char *line, char **fields) {
  int n = 0;
  char *p = line;
  line[strcspn(line, "\r\n")] = '\0';
  fields[n++] = p;
  while ((p = strchr(p, ',')) != NULL && n < MAX_FIELDS) {
    *p++ = '\0';
    fields[n++] = p;
  }
  return n;
}

static int Find(char **fields, int n, const char *name) {
  int i;
  for (i = 0; i < n; ++i)
    if (strcmp(fields[i], name) == 0) return i;
  return -1;
}

int main(int argc, char **argv) {
  static char line[MAX_LINE];
  static const char *const names[CHANNELS] = CHANNEL_NAMES;
  char *fields[MAX_FIELDS];
  char run[256] = "";
  int col_run = -1, col_t = -1, col_bias = -1, col_T[CHANNELS];
  int header_seen = 0, c, n;
  long rows = 0, runs = 0, flagged = 0;
  STATE s;
  FILE *in;
  if (argc != 2) {
    fprintf(stderr, "usage: harness DATA.csv\n");
    return 2;
  }
  in = fopen(argv[1], "r");
  if (!in) {
    fprintf(stderr, "harness: cannot open %s\n", argv[1]);
    return 2;
  }
  while (fgets(line, sizeof line, in)) {
    if (line[0] == '#') continue;
    n = Split(line, fields);
    if (!header_seen) {
      header_seen = 1;
      col_run = Find(fields, n, "run");
      col_t = Find(fields, n, "t_s");
      col_bias = Find(fields, n, "bias_dph");
      for (c = 0; c < CHANNELS; ++c) {
        col_T[c] = Find(fields, n, names[c]);
        if (col_T[c] < 0) {
          fprintf(stderr, "harness: %s has no column %s\n", argv[1], names[c]);
          return 2;
        }
      }
      if (col_run < 0 || col_t < 0 || col_bias < 0) {
        fprintf(stderr, "harness: %s lacks run, t_s or bias_dph\n", argv[1]);
        return 2;
      }
      continue;
    }
    {
      REAL T[CHANNELS];
      REAL out;
      if (strcmp(fields[col_run], run) != 0) {
        strncpy(run, fields[col_run], sizeof run - 1);
        INIT(&s);
        ++runs;
      }
      for (c = 0; c < CHANNELS; ++c) T[c] = (REAL)strtod(fields[col_T[c]], NULL);
      out = UPDATE(&s, (REAL)strtod(fields[col_t], NULL), T, (REAL)strtod(fields[col_bias], NULL));
      printf("%.17g,%d\n", (double)out, s.outside_range);
      ++rows;
      flagged += s.outside_range;
    }
  }
  fclose(in);
  fprintf(stderr, "harness: %ld rows of %ld runs, %ld flagged outside the fitted range\n", rows, runs, flagged);
  return 0;
}
