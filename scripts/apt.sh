# apt-get for the set-up scripts (sourced by setup.sh; needs PY and die()).
# apt-get waits for the package lock: on a fresh machine the system's own
# updater may hold it for minutes after boot.  Wait up to APT_LOCK_WAIT
# seconds (default 900), saying who holds it, then give up with a message.
read -r -a apt_locks <<< "${GCODEKIT_APT_LOCKS:-/var/lib/dpkg/lock-frontend /var/lib/dpkg/lock /var/lib/apt/lists/lock}"
apt_lock_free() {
  "$PY" - "${apt_locks[@]}" <<'PYEOF'
import fcntl, sys
for path in sys.argv[1:]:
    try:
        with open(path, "a") as handle:
            fcntl.lockf(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except FileNotFoundError:
        continue
    except OSError:
        sys.exit(1)
PYEOF
}
apt_lock_holders() {
  local path holders=""
  for path in "${apt_locks[@]}"; do
    holders+=$(lslocks -n -o COMMAND,PID,PATH 2>/dev/null | awk -v p="$path" '$3 == p {print $1 " (pid " $2 ")"}')$'\n'
  done
  printf '%s' "$holders" | grep -v '^$' | sort -u | paste -sd, - || true
}
wait_for_apt_lock() {
  local limit=${APT_LOCK_WAIT:-900} waited=0
  apt_lock_free && return 0
  echo "gcodekit setup: waiting for the package lock (held by $(apt_lock_holders || echo 'another apt or dpkg'));" \
       "up to ${limit} s" >&2
  until apt_lock_free; do
    [ "$waited" -ge "$limit" ] && die "the package lock is still held after ${limit} s by $(apt_lock_holders);" \
      "let that finish (or set APT_LOCK_WAIT to wait longer) and run this again"
    sleep "${APT_LOCK_POLL:-5}"; waited=$((waited + ${APT_LOCK_POLL:-5}))
  done
  echo "gcodekit setup: the package lock is free after ${waited} s" >&2
}
# apt_install WHAT [OPTION|PACKAGE]...: install Debian packages, waiting for the lock first.
apt_install() {
  local what=$1; shift
  local names; names=$(printf '%s\n' "$@" | grep -v '^-' | paste -sd' ' -)
  wait_for_apt_lock
  echo "gcodekit setup: installing $names ($what) with apt-get" >&2
  { apt-get -o DPkg::Lock::Timeout=120 update -qq \
      && DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=120 install -y -qq "$@" >/dev/null; } \
    || die "apt-get could not install $names ($what)"
}
