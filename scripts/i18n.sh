#!/usr/bin/env bash
# The pendant's message catalogs (docs/languages.md): Babel extracts, updates and compiles; the app
# reads the compiled .mo files with the standard library's gettext (tcp_pendant/translation.py).
#
#   scripts/i18n.sh extract        the template locale/tcp_pendant.pot from the code (_(), ngettext, pgettext, N_)
#   scripts/i18n.sh update         each language's .po from the template (a new language: its catalog is created)
#   scripts/i18n.sh pseudo         the pseudo-locale qps from the template (wrapped and accented)
#   scripts/i18n.sh compile        every .po to its .mo (committed: tests/app/test_translation.py checks they match)
#   scripts/i18n.sh all            the four in that order
#
# Needs Babel (the test extra: `. scripts/venv.sh; ensure_venv test`). No babel.cfg: the options are here.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
PY="${PYTHON:-$ROOT/.venv/bin/python}"
LOCALE=app/tcp_pendant/locale
POT=$LOCALE/tcp_pendant.pot
LANGS="de es ru hi zh_Hans ja"      # translation.LANGUAGE_NAMES without the source language (en)

extract() {
  "$PY" -m babel.messages.frontend extract --no-location --sort-output --no-wrap --copyright-holder="the TCP Pendant authors" \
    -k N_ -k ngettext:1,2 -k pgettext:1c,2 -k npgettext:1c,2,3 \
    --project=tcp-pendant --version=0.1 -o "$POT" app/tcp_pendant
}
update() {
  for lang in $LANGS; do
    po=$LOCALE/$lang/LC_MESSAGES/tcp_pendant.po
    if [ -f "$po" ]; then
      "$PY" -m babel.messages.frontend update --no-fuzzy-matching --no-wrap -D tcp_pendant -l "$lang" -i "$POT" -d $LOCALE
    else
      "$PY" -m babel.messages.frontend init --no-wrap -D tcp_pendant -l "$lang" -i "$POT" -d $LOCALE
    fi
  done
}
pseudo() {
  mkdir -p $LOCALE/qps/LC_MESSAGES
  "$PY" scripts/pseudo_locale.py "$POT" $LOCALE/qps/LC_MESSAGES/tcp_pendant.po
}
compile() {
  # Babel's own compile refuses a translation of "95 % radius": it reads "% r" as a %-conversion
  # (a message of ours has str.format placeholders only), so the catalogs are written here with
  # the same writer (babel.messages.mofile.write_mo), without that check; the tests check the
  # {placeholders} of every language instead (tests/app/test_translation.py).
  "$PY" - "$LOCALE" <<'PYCODE'
import sys
from pathlib import Path
from babel.messages.mofile import write_mo
from babel.messages.pofile import read_po
for po in sorted(Path(sys.argv[1]).glob("*/LC_MESSAGES/tcp_pendant.po")):
    with po.open("rb") as f:
        catalog = read_po(f)
    done = sum(1 for m in catalog if m.id and (all(m.string) if isinstance(m.string, tuple) else m.string))
    with po.with_suffix(".mo").open("wb") as f:
        write_mo(f, catalog)
    print(f"{done} of {sum(1 for m in catalog if m.id)} messages translated in {po}")
PYCODE
}

case "${1:-}" in
  extract) extract ;;
  update) update ;;
  pseudo) pseudo ;;
  compile) compile ;;
  all) extract; update; pseudo; compile ;;
  *) echo "usage: scripts/i18n.sh extract|update|pseudo|compile|all" >&2; exit 2 ;;
esac
