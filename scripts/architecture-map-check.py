#!/usr/bin/env python3
"""Every file under crates/*/{src,tests,benches,examples}, fuzz/fuzz_targets and
scripts/ must be named in ARCHITECTURE.md's module map."""
import glob, os, re, sys
os.chdir(sys.argv[1] if len(sys.argv) > 1 else '.')
text = open('ARCHITECTURE.md').read()
block = text.split('## Modules', 1)[1].split('```')[1]
def expand(tok):
    m = re.search(r'\{([^}]*)\}', tok)
    if not m:
        return [tok]
    return [x for alt in m.group(1).split(',') for x in expand(tok[:m.start()] + alt + tok[m.end():])]
named = set(); base = ''
for line in block.splitlines():
    if not line.strip():
        continue
    indent = len(line) - len(line.lstrip())
    col = re.split(r'\s{2,}', line.strip(), maxsplit=1)[0]
    toks = col.split(' ')
    if indent == 0:
        if len(toks) == 1 and toks[0].endswith('/'):
            base = toks[0]; continue
        prefix = ''
    elif line.startswith(' ' * 20) and not line.strip().startswith(('crates', 'fuzz', 'scripts')) and indent > 20:
        continue  # a continuation of the previous description
    else:
        prefix = base
    d = ''
    for tok in toks:
        for e in expand(tok):
            if '/' in e:
                d = e.rsplit('/', 1)[0] + '/'
                named.add(prefix + e)
            else:
                named.add(prefix + d + e)
files = []
for pat in ['crates/*/src/**/*', 'crates/*/tests/**/*', 'crates/*/benches/**/*',
            'crates/*/examples/**/*', 'fuzz/fuzz_targets/**/*', 'scripts/**/*']:
    files += [f for f in glob.glob(pat, recursive=True) if os.path.isfile(f)]
missing = sorted(set(files) - named)
stale = sorted(n for n in named if not os.path.exists(n))
for f in missing: print('not in the map:', f)
for f in stale: print('in the map, no such file:', f)
print(f'{len(set(files))} files, {len(missing)} missing, {len(stale)} stale')
sys.exit(1 if missing or stale else 0)
