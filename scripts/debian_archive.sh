# Sourced by scripts/root and scripts/meshlab_source: Debian's archive as this machine's apt
# reaches it, and apt run on a private state, so that looking packages and sources up in any
# suite never touches the machine's own sources, lists, cache or locks.

# The Debian mirror this machine's apt uses (its first non-security one).
debian_mirror() {
  local uri
  uri=$(grep -hoE '^(URIs:[[:space:]]*|deb[[:space:]]+(\[[^]]*\][[:space:]]+)?)[a-z]+://[^[:space:]]+' \
          /etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources 2>/dev/null |
        grep -oE '[a-z]+://[^[:space:]]+' | grep -v -- '-security' | grep -E '/debian/?$' | head -1)
  echo "${uri:-http://deb.debian.org/debian}"
}

# apt_private STATE TOOL [ARG...]: runs apt-get, apt-cache or apt-helper with everything it keeps
# under STATE (whose sources.list the caller writes). Release files are not checked for expiry:
# the archive may be a frozen snapshot.
apt_private() {
  local state=$1 tool=$2
  shift 2
  mkdir -p "$state/lists/partial" "$state/cache/archives/partial"
  [ -f "$state/status" ] || : >"$state/status"
  "$tool" -o Dir::State::Lists="$state/lists" -o Dir::State::Status="$state/status" \
    -o Dir::Etc::SourceList="$state/sources.list" -o Dir::Etc::SourceParts=/dev/null \
    -o Dir::Cache="$state/cache" -o Debug::NoLocking=1 -o Acquire::Check-Valid-Until=false \
    -o APT::Architecture=amd64 -o APT::Sandbox::User=root "$@"
}

# A sources.list line for SUITE of the machine's mirror: apt_source_line deb|deb-src SUITE
apt_source_line() {
  printf '%s [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] %s %s main\n' "$1" "$(debian_mirror)" "$2"
}
