# Sourced by scripts/vtk-sdk.sh and scripts/pv6-sdk.sh: apt and apt-cache on Debian unstable
# under a private configuration in a folder of the SDK (lists, cache, state), so that nothing
# is installed on the machine and its own apt configuration is left as it is.
#   sid_apt_init DIR [closure]  configure in DIR and refresh the lists if older than 12 h;
#                               `closure`: against an empty dpkg status, so that an install
#                               --download-only resolves a package's whole runtime closure
#   sid_apt ARGS...             apt-get with that configuration
#   sid_version PACKAGE         the upstream version unstable serves (9.6.2 of 9.6.2+dfsg-1)
#   sid_download DIR PACKAGE... those packages' .debs alone into DIR
#   sid_unpack ROOT DEB...      dpkg-deb -x each into ROOT
sid_apt_init() {
  local apt=$1
  mkdir -p "$apt/etc/preferences.d" "$apt/etc/sources.list.d" "$apt/state/lists/partial" \
    "$apt/cache/archives/partial"
  echo "deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] http://deb.debian.org/debian sid main" \
    >"$apt/etc/sources.list"
  SID_APT_OPTS=(-o "Dir::Etc=$apt/etc" -o "Dir::State=$apt/state" -o "Dir::Cache=$apt/cache"
    -o Debug::NoLocking=1 -o APT::Sandbox::User=root -o Acquire::Languages=none)
  if [ "${2:-}" = closure ]; then
    : >"$apt/state/status.empty"
    SID_APT_OPTS+=(-o "Dir::State::status=$apt/state/status.empty")
  fi
  if [ -z "$(find "$apt/state/lists" -maxdepth 1 -name '*Packages*' -mmin -720 2>/dev/null)" ]; then
    apt-get "${SID_APT_OPTS[@]}" -qq update
  fi
}

sid_apt() {
  apt-get "${SID_APT_OPTS[@]}" "$@" 2>&1 | { grep -v "^W: Download is performed unsandboxed" || true; }
  return "${PIPESTATUS[0]}"
}

sid_version() {
  apt-cache "${SID_APT_OPTS[@]}" show --no-all-versions "$1" |
    sed -n 's/^Version: \([0-9.]*\)+.*/\1/p'
}

sid_download() {
  local dir=$1
  shift
  mkdir -p "$dir"
  (cd "$dir" && sid_apt -qq download "$@")
}

sid_unpack() {
  local root=$1 deb
  shift
  mkdir -p "$root"
  for deb in "$@"; do
    dpkg-deb -x "$deb" "$root"
  done
}
