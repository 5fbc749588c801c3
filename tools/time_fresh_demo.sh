#!/bin/bash
# `make demo` as a new user meets it: a fresh Debian 12 root (debootstrap minbase with
# git, make and ca-certificates), this repository's branch cloned into it, then
# `time make demo` in a chroot with every output line stamped with the seconds since
# the start (docs/BENCHMARKS.md). Needs root and Debian's debootstrap.
#
#   tools/time_fresh_demo.sh WORK_DIR [BRANCH] [CA_FILE]
#
# WORK_DIR (outside the repository) keeps the base root as base.tar, so that every run
# starts from the same fresh system, and the logs demo-<time>.log. CA_FILE: a
# certificate authority the root must trust to reach the npm registry over HTTPS
# (a network whose proxy re-signs TLS).
set -euo pipefail
work=$(realpath -m "$1")
branch=${2:-$(git -C "$(dirname "$0")" rev-parse --abbrev-ref HEAD)}
ca=${3:-}
repo=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
root=$work/root
mkdir -p "$work"

unmount() { for m in sys dev/pts dev proc; do if mountpoint -q "$root/$m"; then umount "$root/$m"; fi; done; }
trap unmount EXIT
unmount

if [ ! -f "$work/base.tar" ]; then
  rm -rf "$root"
  debootstrap --variant=minbase --include=git,make,ca-certificates bookworm "$root" http://deb.debian.org/debian
  printf '%s\n' "deb http://deb.debian.org/debian bookworm main" \
    "deb http://deb.debian.org/debian bookworm-updates main" \
    "deb http://deb.debian.org/debian-security bookworm-security main" > "$root/etc/apt/sources.list"
  cp /etc/resolv.conf "$root/etc/resolv.conf"
  if [ -n "$ca" ]; then
    cp "$ca" "$root/usr/local/share/ca-certificates/extra-ca.crt"
    chroot "$root" update-ca-certificates
  fi
  tar -C "$root" -cf "$work/base.tar" .
fi
rm -rf "$root" && mkdir -p "$root" && tar -C "$root" -xf "$work/base.tar"
mount -t proc proc "$root/proc"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
mount --bind /sys "$root/sys"
git clone -q --branch "$branch" "$repo" "$root/root/interpatch"

log=$work/demo-$(date -u +%Y%m%dT%H%M%SZ).log
echo "time_fresh_demo.sh: $log"
{
  echo "start $(date -u +%FT%TZ) load $(cut -d' ' -f1-3 /proc/loadavg) commit $(git -C "$root/root/interpatch" rev-parse --short HEAD)"
  env -i HOME=/root TERM=dumb PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    chroot "$root" /bin/bash -c 'cd /root/interpatch && s=${EPOCHREALTIME/./} && { time make demo; } 2>&1 |
      while IFS= read -r l; do t=${EPOCHREALTIME/./}; printf "%6d.%d %s\n" $(( (t - s) / 1000000 )) $(( (t - s) / 100000 % 10 )) "$l"; done'
  echo "end $(date -u +%FT%TZ) load $(cut -d' ' -f1-3 /proc/loadavg)"
} > "$log" 2>&1
grep -E "installing from|fetch_viewer_deps|npm ci|cmake --|\[1/|Linking CXX executable interpatch|interpatch demo:|^ *[0-9.]+ (real|user|sys)" "$log"
