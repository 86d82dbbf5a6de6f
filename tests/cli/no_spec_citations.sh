#!/usr/bin/env bash
# no_spec_citations.sh RLGTHERM DATA_DIR: the repository stands alone. No tracked file sends its
# reader to a file outside the repository (the sibling folder the project was started from, its
# contract and notes) or to the tracker of work items, and every --help text and message that points to
# a format description points to the repository's own docs.
set -u
bin=$1; data=$2; root=$(cd "$data/../../.." && pwd); d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
# The patterns are split so that this file does not match itself.
up='\.\./'; up+='shared'
spec='SP''EC'
notes='\b(DIAG''NOSIS|PHY''SICS|ARCHI''TECTURE|STY''LE)\b'
tracker='[Ii]ss''ue ?#?[0-9]|[Tt]he iss''ue'
if git -C "$root" rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  git -C "$root" ls-files -z > "$d/files"
else
  (cd "$root" && find . -path ./build -prune -o -path './build-*' -prune -o -path ./.git -prune -o -type f -print0) > "$d/files"
fi
if (cd "$root" && xargs -0 grep -nIE "$up|$spec|$notes|$tracker" < "$d/files"); then
  echo "the files above cite something outside the repository"; exit 1
fi
{
  "$bin" --help
  # Every verb the top-level help lists.
  for verb in $("$bin" --help | awk '/^Subcommands:/ { on = 1; next } on && NF { print $1 }'); do "$bin" "$verb" --help; done
  "$bin" fit "$d/missing.csv"
  printf 'gyro = "%s"\n[[effects]]\nname = "thermal.nonsense"\ntarget = "T1"\n[[runs]]\nid = "x"\nambient = { profile = "constant", value_C = 1 }\n' \
    "$root/scenarios/gyros/default.toml" > "$d/effect.toml"
  "$bin" simulate "$d/effect.toml" -o "$d/out.csv"
} > "$d/all.txt" 2>&1
if grep -nE "$spec|$up" "$d/all.txt"; then echo "user-facing text cites a file outside the repository (above)"; exit 1; fi
grep -q "docs/data-format.md" "$d/all.txt" || { echo "no pointer to docs/data-format.md"; exit 1; }
# Every docs/ page the help and messages name exists (a mangled path, "docs/a->md", went unseen).
for page in $(grep -oE 'docs/[^ ),;:"]*' "$d/all.txt" | sed 's/[.]$//' | sort -u); do
  [ -f "$root/$page" ] || { echo "help or a message names $page, which is not in the repository:"; grep -nF "$page" "$d/all.txt"; exit 1; }
done
grep -q "the catalog (scenarios/README.md, Effects)" "$d/all.txt" || { echo "unknown effect message"; cat "$d/all.txt"; exit 1; }
echo "$(tr -cd '\0' < "$d/files" | wc -c) tracked files cite nothing outside the repository;" \
     "$(wc -l < "$d/all.txt") lines of help and messages point to its docs"
