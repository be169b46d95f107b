#!/usr/bin/env python3
# File-level import cycles in each crate (crate::/super:: paths outside comments and test modules).
# Prints each strongly connected component of the module graph; exits 1 if there is one.
# Run from the repository root: python3 scripts/import-cycles.py
import re,os,sys,itertools
def mods(root):
    files={}
    for dp,_,fs in os.walk(root):
        for f in fs:
            if f.endswith('.rs'):
                p=os.path.join(dp,f); rel=os.path.relpath(p,root)[:-3]
                m=rel.replace('/mod','').replace('/','::')
                if m in('lib','main'): m=''
                files[m]=open(p).read()
    return files
found=False
for crate in ['runtime/src','scene/src','eval/src','viewer/src','precompute/src','tables/src','src']:
    fs=mods(crate); edges=set()
    for m,src in fs.items():
        src=re.sub(r'#\[cfg\(test\)\]\s*mod tests\s*\{.*','',src,flags=re.S)
        src=re.sub(r'//[^\n]*','',src)
        for t in fs:
            if t==m or not t: continue
            # crate::t or super:: references
            if re.search(r'crate::'+re.escape(t)+r'\b(?!_)',src): edges.add((m,t))
            if '::' in m or '::' in t:
                pass
            parent=m.rsplit('::',1)[0] if '::' in m else ''
            tail=t[len(parent)+2:] if parent and t.startswith(parent+'::') else (t if not parent else None)
            if tail and '::' not in tail and re.search(r'super::'+re.escape(tail)+r'\b',src): edges.add((m,t))
    # child->parent edges via super::X where X item in parent file not tracked; detect 2-cycles and longer via SCC
    g={}
    for a,b in edges: g.setdefault(a,set()).add(b)
    idx={};low={};st=[];on=set();sccs=[];c=[0]
    sys.setrecursionlimit(10000)
    def sc(v):
        idx[v]=low[v]=c[0];c[0]+=1;st.append(v);on.add(v)
        for w in g.get(v,()):
            if w not in idx: sc(w);low[v]=min(low[v],low[w])
            elif w in on: low[v]=min(low[v],idx[w])
        if low[v]==idx[v]:
            comp=[]
            while True:
                w=st.pop();on.discard(w);comp.append(w)
                if w==v:break
            if len(comp)>1: sccs.append(comp)
    for v in list(g):
        if v not in idx: sc(v)
    print(crate, sccs or 'no cycles')
    found = found or bool(sccs)
sys.exit(1 if found else 0)
