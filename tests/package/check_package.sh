#!/usr/bin/env bash
# check_package.sh BUILD_DIR SOURCE_DIR: builds the .deb as `make package` does (into a temporary folder) and
# checks what a Debian user gets: a stripped binary and module whose debug symbols are in the
# -dbgsym package under their build IDs, the man page, completions, desktop entry, MIME types,
# AppStream metadata, copyright, changelog and docs in their places, the MIME types resolving, and
# no lintian error.
set -euo pipefail
build=$(cd "$1" && pwd)
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

(cd "$work" && cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/out" >"$work/cpack.log" 2>&1) ||
  { cat "$work/cpack.log" >&2; exit 1; }
deb=$(ls "$work"/out/nelf_*.deb)
dbgsym=$(ls "$work"/out/nelf-dbgsym_*.ddeb 2>/dev/null || true)
[ -n "$dbgsym" ] || { fail "no nelf-dbgsym package"; ls "$work/out" >&2; }

contents=$(dpkg-deb -c "$deb" | awk '{print $6}' | sed 's|^\./|/|')
for f in /usr/bin/nelf /usr/lib/nelf/nelf-oiio.so /usr/share/man/man1/nelf.1.gz \
  /usr/share/bash-completion/completions/nelf /usr/share/zsh/vendor-completions/_nelf \
  /usr/share/fish/vendor_completions.d/nelf.fish /usr/share/applications/nelf.desktop \
  /usr/share/mime/packages/nelf.xml /usr/share/metainfo/nelf.metainfo.xml /usr/share/doc/nelf/copyright \
  /usr/share/doc/nelf/changelog.gz /usr/share/doc/nelf/README.md; do
  grep -qx "$f" <<<"$contents" || fail "$f is not in the package"
done
# Every doc the README links to is installed beside it.
for doc in $(grep -o '](docs/[^)#]*' "$src/README.md" | sed 's/^](//' | sort -u); do
  grep -qx "/usr/share/doc/nelf/$doc" <<<"$contents" || fail "README links $doc, which is not installed"
done
# And every picture the docs show is installed beside them.
for picture in $(cat "$src"/docs/*.md | grep -o '](pictures/[^)#]*' | sed 's/^](//' | sort -u); do
  grep -qx "/usr/share/doc/nelf/docs/$picture" <<<"$contents" || fail "docs show $picture, which is not installed"
done

dpkg-deb -x "$deb" "$work/root"
for elf in usr/bin/nelf usr/lib/nelf/nelf-oiio.so; do
  file -b "$work/root/$elf" | grep ', stripped' >/dev/null || fail "$elf is not stripped: $(file -b "$work/root/$elf")"
  if [ -n "$dbgsym" ]; then
    id=$(readelf -n "$work/root/$elf" | sed -n 's/.*Build ID: //p')
    grep -q "usr/lib/debug/.build-id/${id:0:2}/${id:2}.debug" <<<"$(dpkg-deb -c "$dbgsym")" ||
      fail "$elf: no usr/lib/debug/.build-id/${id:0:2}/${id:2}.debug in the dbgsym package"
  fi
done
"$work/root/usr/bin/nelf" --version >/dev/null || fail "the packaged nelf does not run"

# The MIME types nelf.desktop names resolve from the shared database plus nelf.xml.
mkdir -p "$work/mime/packages"
cp /usr/share/mime/packages/freedesktop.org.xml "$work/root/usr/share/mime/packages/nelf.xml" "$work/mime/packages/"
update-mime-database "$work/mime" 2>"$work/mime.log" || fail "update-mime-database: $(cat "$work/mime.log")"
for glob in 'image/x-jps:\*.jps' 'image/x-mpo:\*.mpo' 'video/x-matroska-3d:\*.mk3d'; do
  grep -qx "$glob" "$work/mime/globs" || fail "MIME glob ${glob//\\/} does not resolve"
done
for type in $(sed -n 's/^MimeType=//p' "$work/root/usr/share/applications/nelf.desktop" | tr ';' ' '); do
  grep -q "^$type$\|^$type " "$work/mime/types" || fail "nelf.desktop names $type, which no MIME package defines"
done

# AppStream: no error. (It warns cid-desktopapp-is-not-rdns: the ID would need a domain nelf owns.)
appstreamcli validate --no-net "$work/root/usr/share/metainfo/nelf.metainfo.xml" >"$work/as.log" 2>&1 || true
cat "$work/as.log"
if grep -q '^E: ' "$work/as.log"; then fail "appstreamcli validate reports errors"; fi

# lintian: no error (warnings are listed in the log, for a person to read).
lintian --tag-display-limit 0 "$deb" >"$work/lintian.log" 2>&1 || true
cat "$work/lintian.log"
if grep -q '^E: ' "$work/lintian.log"; then fail "lintian reports errors"; fi

[ "$failures" -eq 0 ] || { echo "$failures check(s) failed" >&2; exit 1; }
echo "package checks passed: $(basename "$deb") ${dbgsym:+and $(basename "$dbgsym")}"
