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
  mkdir -p "$work/t/core/numerics" "$work/t/core/qp/detail" "$work/t/core/modes" "$work/t/models" "$work/t/app" \
    "$work/t/input/net" "$work/t/ui"
  echo '#include "core/numerics/a.hpp"' >"$work/t/core/qp/q.hpp"
  echo '#include "core/qp/detail/k.hpp"' >"$work/t/core/qp/q.cpp"
  echo '' >"$work/t/core/qp/detail/k.hpp"
  echo '#include "core/qp/q.hpp"' >"$work/t/core/modes/m.hpp"
  echo '' >"$work/t/core/numerics/a.hpp"
  echo 'add_subdirectory(numerics)' >"$work/t/core/CMakeLists.txt"
  echo '#include <Eigen/Core>' >"$work/t/models/model.hpp"
  echo '#include "core/modes/m.hpp"' >"$work/t/app/main.cpp"
  printf '#include "core/modes/m.hpp"\n#include "input/net/peer.hpp"\n#include "ui/screen.hpp"\n' >>"$work/t/app/main.cpp"
  printf '#include <GLFW/glfw3.h>\n#include "ui/screen.hpp"\n' >"$work/t/app/window.cpp"
  printf '#include "core/modes/m.hpp"\n#include "models/model.hpp"\n' >"$work/t/input/device.hpp"
  printf '#include "input/device.hpp"\n#include <dds/dds.h>\n' >"$work/t/input/net/peer.hpp"
  printf '#include "input/device.hpp"\n#include "core/modes/m.hpp"\n' >"$work/t/ui/screen.hpp"
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
clean_tree; echo '#include "input/device.hpp"' >>"$work/t/core/modes/m.hpp"
expect "the engine includes an outer layer" 1 "the engine includes input/device.hpp"
clean_tree; echo '#include "input/net/peer.hpp"' >>"$work/t/input/device.hpp"
expect "a device includes the network" 1 "input/ (devices) includes input/net/peer.hpp"
clean_tree; echo '#include "ui/screen.hpp"' >>"$work/t/input/device.hpp"
expect "a device includes the UI" 1 "input/ (devices) includes ui/screen.hpp"
clean_tree; echo '#include "ui/screen.hpp"' >>"$work/t/input/net/peer.hpp"
expect "the network includes the UI" 1 "the network (input/net/) includes ui/screen.hpp"
clean_tree; echo '#include "app/cli.hpp"' >>"$work/t/input/net/peer.hpp"
expect "the network includes the app" 1 "the network (input/net/) includes app/cli.hpp"
clean_tree; echo '#include "input/net/peer.hpp"' >>"$work/t/ui/screen.hpp"
expect "the UI includes the network" 1 "ui/ includes input/net/peer.hpp"
clean_tree; echo '#include "app/cli.hpp"' >>"$work/t/ui/screen.hpp"
expect "the UI includes the app" 1 "ui/ includes app/cli.hpp"
clean_tree; echo '#include "tests/helpers.hpp"' >>"$work/t/app/main.cpp"
expect "the app includes the tests" 1 "app/ includes tests/helpers.hpp"
clean_tree; echo '#include <GLFW/glfw3.h>' >>"$work/t/ui/screen.hpp"
expect "a backend header in the UI" 1 "ui/screen.hpp:3:.*a window-system or GL backend header"
clean_tree; echo '#include <EGL/egl.h>' >>"$work/t/app/main.cpp"
expect "a backend header outside the backends" 1 "app/main.cpp:5:.*a window-system or GL backend header"
clean_tree; echo '#include <SDL2/SDL.h>' >>"$work/t/ui/screen.hpp"
expect "SDL in the UI" 1 "an SDL or DDS header outside input/"
echo "$pass passed, $fails failed"
[ "$fails" -eq 0 ]
