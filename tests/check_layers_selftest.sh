#!/usr/bin/env bash
# check_layers.sh must catch each kind of violation: a tree with exactly one of them is
# rejected with a message naming it, and the clean tree is accepted.
# Usage: check_layers_selftest.sh CHECK_LAYERS_SH
set -u
check=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pass=0
fails=0
clean_tree() {
  rm -rf "$work/t"
  mkdir -p "$work/t/core/numerics" "$work/t/core/qp/detail" "$work/t/core/modes" "$work/t/models" "$work/t/app"
  echo '#include "core/numerics/a.hpp"' >"$work/t/core/qp/q.hpp"
  echo '#include "core/qp/detail/k.hpp"' >"$work/t/core/qp/q.cpp"
  echo '' >"$work/t/core/qp/detail/k.hpp"
  echo '#include "core/qp/q.hpp"' >"$work/t/core/modes/m.hpp"
  echo '' >"$work/t/core/numerics/a.hpp"
  echo 'add_subdirectory(numerics)' >"$work/t/core/CMakeLists.txt"
  echo '#include <Eigen/Core>' >"$work/t/models/model.hpp"
  echo '#include "core/modes/m.hpp"' >"$work/t/app/main.cpp"
}
expect() {  # expect NAME WANT_STATUS PATTERN
  local out status
  out=$(bash "$check" "$work/t" 2>&1)
  status=$?
  if [ "$status" -eq "$2" ] && grep -q -- "$3" <<<"$out"; then
    pass=$((pass + 1))
  else
    echo "FAILED: $1 (exit $status): $out"
    fails=$((fails + 1))
  fi
}
clean_tree
expect "clean tree accepted" 0 "0 violations"
clean_tree; echo '#include "core/modes/m.hpp"' >>"$work/t/core/numerics/a.hpp"
expect "include up the path" 1 "layer numerics includes core/modes/m.hpp from the higher layer"
clean_tree; echo '#include "core/qp/detail/k.hpp"' >>"$work/t/core/modes/m.hpp"
expect "internal header of another layer" 1 "internal to layer qp"
clean_tree; echo 'int x;' >"$work/t/core/loose.cpp"
expect "file at core's top level" 1 "core/loose.cpp: a file at core/'s top level"
clean_tree; echo '#include <imgui.h>' >>"$work/t/core/modes/m.hpp"
expect "UI header in the engine" 1 "UI, SDL or DDS header"
clean_tree; echo '#include <SDL2/SDL.h>' >>"$work/t/models/model.hpp"
expect "SDL header in models" 1 "UI, SDL or DDS header"
clean_tree; echo '#include "core/numerics/a.hpp"' >>"$work/t/models/model.hpp"
expect "models include the engine" 1 "models/ includes the engine"
clean_tree; echo '#include "core/qp/detail/k.hpp"' >>"$work/t/app/main.cpp"
expect "app includes an internal header" 1 "internal header of the engine"
clean_tree; mkdir -p "$work/t/core/gui"; echo '' >"$work/t/core/gui/g.hpp"
expect "folder that is no layer" 1 "core/gui/: not a layer"
echo "$pass passed, $fails failed"
[ "$fails" -eq 0 ]
