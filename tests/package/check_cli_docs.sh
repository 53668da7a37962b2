#!/usr/bin/env bash
# check_cli_docs.sh NELF DOCS_DIR: the man page and the bash, zsh and fish completions generated
# into DOCS_DIR (nelf.1, nelf.bash, _nelf, nelf.fish) name every subcommand and every option that
# `NELF --help` and `NELF COMMAND --help` list, and nothing else: the page and completions are
# generated from the CLI's definitions, and this catches a generator that misses or invents one.
# The completions are run (bash and fish), not only read; the page is rendered as lintian does.
set -euo pipefail
# Under pipefail a `grep -q` that stops reading at its match makes the writer die of SIGPIPE when it
# writes on (bash writes each line of printf apart): the greps below read their whole input.
nelf=$1
docs=$2
failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

# The subcommands and options, as nelf's own help prints them; each help text is asked once (every
# check below reads it again, and nelf takes a tenth of a second to start).
declare -A help_text
help_text[_]=$("$nelf" --help)
commands=$(awk '/^Subcommands:/ {on = 1; next} on && /^  [a-z]/ {print $1}' <<<"${help_text[_]}")
[ -n "$commands" ] || { echo "FAIL: no subcommands in nelf --help" >&2; exit 1; }
for c in $commands; do help_text[$c]=$("$nelf" "$c" --help); done
# Options of one help text: the "-y,--overwrite TEXT ..." column of each "  -..." line.
help_options() {
  awk '/^  -/ {n = split($1, names, ","); for (i = 1; i <= n; i++) print names[i]}' <<<"${help_text[${1:-_}]}" | sort -u
}
# Positionals of one help text: the names in the "Positionals:" section.
help_positionals() {
  awk '/^[A-Za-z].*:$/ {on = ($0 == "Positionals:"); next} on && /^  [a-z]/ {print $1}' <<<"${help_text[$1]}"
}
same_set() {  # same_set WHAT EXPECTED ACTUAL
  local missing extra
  missing=$(comm -23 <(printf '%s\n' "$2" | sort -u) <(printf '%s\n' "$3" | sort -u) | tr '\n' ' ')
  extra=$(comm -13 <(printf '%s\n' "$2" | sort -u) <(printf '%s\n' "$3" | sort -u) | tr '\n' ' ')
  [ -z "$missing" ] || fail "$1: missing $missing"
  [ -z "$extra" ] || fail "$1: not in nelf's help: $extra"
}

# ---- man page ----
page=$docs/nelf.1
# Options of a roff section: the bold names that open a .TP item ("\fB\-y\fR, \fB\-\-overwrite\fR ...").
roff_options() {
  awk '/^\.TP$/ {getline; print}' | grep -o '\\fB\\-[^\\]*\(\\-[^\\]*\)*\\fR' | sed 's/\\fB//; s/\\fR//; s/\\-/-/g' | sort -u
}
section() {  # the lines of ".SS NAME" up to the next .SS or .SH
  awk -v name="$1" '$0 == ".SS " name {on = 1; next} on && /^\.S[SH] / {on = 0} on'
}
same_set "nelf.1 commands" "$commands" "$(awk '/^\.SS / {print $2}' "$page")"
same_set "nelf.1 OPTIONS" "$(help_options)" \
  "$(awk '/^\.SH OPTIONS/ {on = 1; next} on && /^\.S[SH] / {on = 0} on' "$page" | roff_options)"
for c in $commands; do
  same_set "nelf.1 $c options" "$(help_options "$c")" "$(section "$c" <"$page" | roff_options)"
  for p in $(help_positionals "$c"); do
    section "$c" <"$page" | grep -x "\\\\fI${p^^}\\\\fR" >/dev/null || fail "nelf.1 $c: positional ${p^^} not described"
  done
done
# Rendered as lintian checks pages: no groff warning, no line that does not fit.
warnings=$(LC_ALL=C.UTF-8 MANROFFSEQ='' MANWIDTH=80 man --warnings -E UTF-8 -l -Tutf8 -Z "$page" 2>&1 >/dev/null)
[ -z "$warnings" ] || fail "nelf.1 renders with warnings: $warnings"

# ---- bash: run the completion function as bash would ----
bash_complete() {  # bash_complete WORD... : what completing the last word offers
  bash -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _nelf; printf "%s\n" "${COMPREPLY[@]}"' \
    _ "$docs/nelf.bash" "$@"
}
same_set "bash: nelf <TAB>" "$commands" "$(bash_complete nelf '')"
same_set "bash: nelf -<TAB>" "$(help_options)" "$(bash_complete nelf -)"
for c in $commands; do
  same_set "bash: nelf $c -<TAB>" "$(help_options "$c")" "$(bash_complete nelf "$c" -)"
done
[ "$(bash_complete nelf simulate --eye '')" = "$(printf 'left\nright')" ] || fail "bash: --eye values"
bash_complete nelf convert --profile '' | grep -x hmz-t1 >/dev/null || fail "bash: --profile does not offer the built-in profiles"

# ---- fish: ask fish itself (complete -C) ----
if command -v fish >/dev/null; then
  fish -n "$docs/nelf.fish" || fail "nelf.fish: syntax"
  fish_complete() { fish --no-config -c "source '$docs/nelf.fish'; complete -C '$1'" | cut -f1 | sort -u; }
  same_set "fish: nelf <TAB>" "$commands" "$(fish_complete 'nelf ' | grep -v '^-')"
  for c in $commands; do
    same_set "fish: nelf $c -<TAB>" "$(help_options "$c")" "$(fish_complete "nelf $c -")"
  done
else
  fail "fish is not installed (packaging/install-deps.sh installs it)"
fi

# ---- zsh: parse it, and read each command's _arguments specs ----
if command -v zsh >/dev/null; then
  zsh -n "$docs/_nelf" || fail "_nelf: syntax"
  zsh_options() {  # the option names of the specs in block "NAME)" up to ";;"
    awk -v name="$1" '$1 == name ")" {on = 1; next} on && /;;/ {on = 0} on' "$docs/_nelf" |
      grep -o "^ *'([^)]*)'\|^ *'-[^[]*\[\|^ *{[^}]*}" | grep -o -- '-[-a-z0-9]*' | sort -u
  }
  for c in $commands; do
    same_set "zsh: nelf $c" "$(help_options "$c")" "$(zsh_options "$c")"
  done
  same_set "zsh: commands" "$commands" "$(awk "/^    commands=\(/ {on = 1; next} on && /^    \)/ {on = 0} on" "$docs/_nelf" | sed "s/^ *'//; s/:.*//")"
else
  fail "zsh is not installed (packaging/install-deps.sh installs it)"
fi

[ "$failures" -eq 0 ] || { echo "$failures check(s) failed" >&2; exit 1; }
echo "man page and bash, zsh and fish completions match nelf's help: $(echo $commands | wc -w) commands"
