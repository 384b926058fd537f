#!/usr/bin/env bash
# The engine's layers (core/CMakeLists.txt) point one way along the data path:
#   base < numerics < qp < nlp < control < scenario < modes < recording < runtime < history
# A file in core/<L>/ may include only core/<M>/ headers with M at or below L; headers in
# core/<L>/detail/ are internal to L (tests may include them); core/ has no file of its own
# besides CMakeLists.txt; core/ and models/ never include UI, SDL or DDS headers, and models/
# never includes core/. The outer layers point the same way:
#   core, models < input (devices) < input/net (network peers) < ui < app
# input/ may include core/, models/ and input/; input/net/ also input/net/; ui/ core/, models/,
# input/ (not the network) and ui/; app/ wires them all; core/ and models/ include none of them.
# Usage: check_layers.sh SOURCE_DIR. Prints each violation; exit 1 if any.
set -u
src=$1
layers=(base numerics qp nlp control scenario modes recording runtime history)
rank() {
  local i
  for i in "${!layers[@]}"; do [ "${layers[$i]}" = "$1" ] && { echo "$i"; return; }; done
  echo -1
}
violations=0
fail() { echo "$1"; violations=$((violations + 1)); }

for f in "$src"/core/*; do
  [ -f "$f" ] && [ "$(basename "$f")" != CMakeLists.txt ] && fail "core/$(basename "$f"): a file at core/'s top level (it belongs to a layer)"
done
for d in "$src"/core/*/; do
  name=$(basename "$d")
  [ "$(rank "$name")" -ge 0 ] || fail "core/$name/: not a layer (${layers[*]})"
done

checked=0
while IFS= read -r f; do
  rel=${f#"$src"/}
  own=$(echo "$rel" | cut -d/ -f2)
  own_rank=$(rank "$own")
  checked=$((checked + 1))
  while IFS=: read -r line inc; do
    layer=$(echo "$inc" | cut -d/ -f2)
    r=$(rank "$layer")
    if [ "$r" -lt 0 ]; then
      fail "$rel:$line: includes $inc, which is in no layer"
    elif [ "$r" -gt "$own_rank" ]; then
      fail "$rel:$line: layer $own includes $inc from the higher layer $layer"
    elif [[ "$inc" == core/*/detail/* ]] && [ "$layer" != "$own" ]; then
      fail "$rel:$line: includes $inc, internal to layer $layer"
    fi
  done < <(grep -noE '^\s*#\s*include\s*"core/[^"]+"' "$f" | sed -E 's/^([0-9]+):.*"(core\/[^"]+)"/\1:\2/')
done < <(find "$src/core" -mindepth 2 -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.in' \) | sort)

while IFS= read -r hit; do
  fail "${hit#"$src"/}: UI, SDL or DDS header in the engine"
done < <(grep -rnE '^\s*#\s*include\s*[<"](imgui|GLFW/|SDL|dds/|EGL/|GL/|epoxy/)' "$src/core" "$src/models" 2>/dev/null)
while IFS= read -r hit; do
  fail "${hit#"$src"/}: models/ includes the engine"
done < <(grep -rnE '^\s*#\s*include\s*"core/' "$src/models" 2>/dev/null)
while IFS= read -r hit; do
  fail "${hit#"$src"/}: includes an internal header of the engine"
done < <(grep -rnE '^\s*#\s*include\s*"core/[^"]*/detail/' "$src/app" "$src/ui" "$src/input" 2>/dev/null)

# outer DIR LABEL ALLOWED_REGEX [EXCLUDED_SUBDIR]: every project include of DIR's files (those
# naming one of the project's folders) must match ALLOWED_REGEX.
outer() {
  local dir=$1 label=$2 allowed=$3 skip=${4:-}
  [ -d "$src/$dir" ] || return 0
  while IFS= read -r f; do
    [ -n "$skip" ] && [[ "$f" == "$src/$skip/"* ]] && continue
    outer_checked=$((outer_checked + 1))
    while IFS=: read -r line inc; do
      [[ "$inc" =~ $allowed ]] || fail "${f#"$src"/}:$line: $label includes $inc, which is not below it on the data path"
    done < <(grep -noE '^\s*#\s*include\s*"[^"]+/[^"]+"' "$f" |
             sed -E 's/^([0-9]+):.*"([^"]+)"/\1:\2/')
  done < <(find "$src/$dir" -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.h' \) | sort)
}
outer_checked=0
outer core "the engine" '^(core|models)/'
outer models "models/" '^models/'
outer input "input/ (devices)" '^(core|models)/|^input/[^/]+$' input/net
outer input/net "the network (input/net/)" '^(core|models|input)/'
outer ui "ui/" '^(core|models|ui)/|^input/[^/]+$'
outer app "app/" '^(core|models|input|ui|app)/'
# The window system and GL backends are wired only in main's backends (app/window.*,
# app/offscreen.*); SDL and DDS only in the input layer that owns the device or the peer.
while IFS= read -r hit; do
  case "${hit#"$src"/}" in app/window.* | app/offscreen.*) continue ;; esac
  fail "${hit#"$src"/}: a window-system or GL backend header outside app/window and app/offscreen"
done < <(grep -rnE '^\s*#\s*include\s*[<"](GLFW/|EGL/|GL/|epoxy/|imgui_impl_)' "$src/app" "$src/ui" "$src/input" 2>/dev/null)
while IFS= read -r hit; do
  fail "${hit#"$src"/}: an SDL or DDS header outside input/"
done < <(grep -rnE '^\s*#\s*include\s*[<"](SDL|dds/)' "$src/app" "$src/ui" 2>/dev/null)

echo "layers: $checked engine files and $outer_checked outer files checked, $violations violations"
[ "$checked" -gt 0 ] && [ "$outer_checked" -gt 0 ] && [ "$violations" -eq 0 ]
