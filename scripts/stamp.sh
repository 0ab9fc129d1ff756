# Sourced by every script that makes a results page (docs/results-*.md): `stamp COMMAND...`
# prints the page's stamp, the line tests/house.rs reads and docs/defaults.md dates:
#
#   > Made by `COMMAND` at COMMIT (YYYY-MM-DD HH:MM UTC) on N cores of CPU; settings: ENV.
#
# COMMIT is HEAD, with "+changes" when the tree differs from it (a page made so cannot be
# made again from a commit: commit first); the time is the commit's, so a page's place
# among the default's changes does not depend on when it ran. ENV is every RAYON_* and SLF_*
# variable set: the settings a script reads beside its arguments.
stamp() {
  local hash when dirty="" cpu settings
  hash=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
  when=$(TZ=UTC git log -1 --format=%cd --date=format-local:'%Y-%m-%d %H:%M' HEAD 2>/dev/null || echo unknown)
  git diff --quiet HEAD -- 2>/dev/null || dirty="+changes"
  cpu=$(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2 | sed 's/^ *//')
  settings=$(env | { grep -E '^(RAYON_[A-Z_]+|SLF_[A-Z_]+)=' || true; } | sort | tr '\n' ' ' | sed 's/ $//')
  echo "> Made by \`$*\` at $hash$dirty ($when UTC) on $(nproc) cores of ${cpu:-an unknown CPU}${settings:+; settings: $settings}."
}

# page_head TITLE COMMAND...: a results page's title and its stamp, each with a blank line after.
page_head() {
  local title=$1
  shift
  printf '# %s\n\n' "$title"
  stamp "$@"
  echo
}
