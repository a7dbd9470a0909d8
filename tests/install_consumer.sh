#!/usr/bin/env bash
# Installs the built project into a scratch prefix, then builds tests/consumer against it twice:
# with CMake (find_package(isohex CONFIG), isohex::isohex) and with pkg-config; runs both and the
# installed CLI. Usage: install_consumer.sh BUILD_DIR SCRATCH_DIR
set -euo pipefail
build=$1
scratch=$2
src=$(cd "$(dirname "$0")/consumer" && pwd)
rm -rf "$scratch"
mkdir -p "$scratch"
prefix=$scratch/prefix
cmake --install "$build" --prefix "$prefix" > "$scratch/install.log"
test -x "$prefix/bin/isohex"
"$prefix/bin/isohex" --version

cmake -S "$src" -B "$scratch/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release > "$scratch/configure.log"
cmake --build "$scratch/cmake-build" > "$scratch/build.log"
"$scratch/cmake-build/consumer" "$scratch/cmake.vtu"

pc_dir=$(dirname "$(find "$prefix" -name isohex.pc | head -n 1)")
PKG_CONFIG_PATH=$pc_dir pkg-config --exists isohex
# shellcheck disable=SC2046
g++ -O1 "$src/main.cpp" -o "$scratch/pc-consumer" $(PKG_CONFIG_PATH=$pc_dir pkg-config --cflags --libs isohex)
"$scratch/pc-consumer" "$scratch/pc.vtu"
cmp "$scratch/cmake.vtu" "$scratch/pc.vtu"
echo "install_consumer: the CMake package and pkg-config both build a working program"
