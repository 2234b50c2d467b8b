#!/usr/bin/env bash
# Installs the Debian 12 packages libmorph needs, if any is missing. Needs root (or sudo).
set -euo pipefail
packages=(build-essential cmake libcgal-dev libopenmesh-dev libtbb-dev libboost-program-options-dev
          doctest-dev libgmp-dev libmpfr-dev libbenchmark-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "setup: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
