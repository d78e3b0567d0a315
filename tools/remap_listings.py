"""Shift the line references of docs/*.md (`path:a-b`, (path#Ln)) after an edit: each file's
lines are mapped from revision BASE (default HEAD) to the working tree with difflib. Run it once
per edit against the revision the references were true for: BASE=<rev> python3 tools/remap_listings.py docs/listings.md
tests/listings.rs then checks that every range starts at its identifier."""
import re, subprocess, difflib, sys, os
BASE = os.environ.get('BASE', 'HEAD')
os.chdir(subprocess.run(['git','rev-parse','--show-toplevel'],capture_output=True,text=True,check=True).stdout.strip())
def old_new_map(path):
    try:
        old = subprocess.run(['git','show',f'{BASE}:{path}'],capture_output=True,text=True,check=True).stdout.split('\n')
    except subprocess.CalledProcessError:
        return None
    new = open(path).read().split('\n')
    if old == new: return None
    m = {}
    sm = difflib.SequenceMatcher(a=old, b=new, autojunk=False)
    for tag,i1,i2,j1,j2 in sm.get_opcodes():
        if tag == 'equal':
            for k in range(i2-i1): m[i1+k+1] = j1+k+1
        else:
            for k in range(i2-i1): m[i1+k+1] = j1 + min(k, max(j2-j1-1,0)) + 1
    return m
cache = {}
def mp(path, line):
    if path not in cache: cache[path] = old_new_map(path)
    m = cache[path]
    if m is None: return line
    return m.get(line, line)
for doc in sys.argv[1:]:
    text = open(doc).read()
    base = os.path.dirname(doc)
    def sub_range(mo):
        path, a, b = mo.group(1), int(mo.group(2)), mo.group(3)
        na = mp(path, a)
        if b: return f"`{path}:{na}-{mp(path, int(b))}`"
        return f"`{path}:{na}`"
    text = re.sub(r'`((?:src|glsl|tests|scripts|tools)/[^`:\s]+):(\d+)(?:-(\d+))?`', sub_range, text)
    def sub_link(mo):
        rel, line = mo.group(1), int(mo.group(2))
        path = os.path.normpath(os.path.join(base, rel))
        return f"({rel}#L{mp(path, line)}"
    text = re.sub(r'\(((?:\.\./)*(?:src|glsl|tests|scripts|tools)/[^)#\s]+)#L(\d+)', sub_link, text)
    open(doc, 'w').write(text)
