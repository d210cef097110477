#!/usr/bin/env bash
# page_modes_kodak.sh BUILD_DIR OUTDIR [IMAGES...]: issue 19's photograph target on whole page
# files. Every image (default: the 24 Kodak PNGs) is built at DCT q50, 75, 90 and 95 with and
# without the per-page mode decision (one thread, every level); then the bytes (stored pages, and
# whole files) against the mean PSNR per image (the layer's psnr_db), the BD-rate of modes over
# --no-page-modes (piecewise-linear and cubic in log bytes over the PSNR range both cover), and
# the decode speed of the same files side by side (vtbake-bench decode, 3 alternating rounds,
# median). Run it through /work/heavy; it takes about 2 minutes of CPU.
set -euo pipefail
bin=$(readlink -f "$1"); out=$2; shift 2
images=("$@")
[ ${#images[@]} -gt 0 ] || images=(/work/shared/testdata/images/kodak/*.png)
mkdir -p "$out"
for q in 50 75 90 95; do
  for img in "${images[@]}"; do
    b=$(basename "$img" .png)
    "$bin/cli/vtbake" --threads 1 -q build "$img" -o "$out/$b.q$q.modes.vtpf" --codec dct:$q \
      --json > "$out/$b.q$q.modes.json"
    "$bin/cli/vtbake" --threads 1 -q build "$img" -o "$out/$b.q$q.nomodes.vtpf" --codec dct:$q \
      --no-page-modes --json > "$out/$b.q$q.nomodes.json"
  done
done
: > "$out/decode.txt"
for round in 1 2 3; do
  for q in 50 75 90 95; do
    for m in nomodes modes; do
      echo "$round $q $m $("$bin/bench/vtbake-bench" -q decode --repeats 5 "$out"/*.q$q.$m.vtpf)" \
        >> "$out/decode.txt"
    done
  done
done
uptime
python3 - "$out" <<'PY'
import json,glob,sys,math,os
D=sys.argv[1]
Q=[50,75,90,95]
imgs=sorted(set(os.path.basename(f).split('.')[0] for f in glob.glob(D+'/*.json')))
def load(q,m):
    st=[];fi=[];ps=[];modes={}
    for i in imgs:
        d=json.load(open(f'{D}/{i}.q{q}.{m}.json'))
        st.append(d['bytes']['stored']);fi.append(d['bytes']['file']);ps.append(d['layers'][0]['psnr_db'])
        for k,v in d['layers'][0].get('dct_modes',{}).items(): modes[k]=modes.get(k,0)+v
    return st,fi,ps,modes
mean=lambda a:sum(a)/len(a)
def interp(x,xs,ys):
    # piecewise linear, xs increasing
    if x<=xs[0]: return ys[0]
    for j in range(1,len(xs)):
        if x<=xs[j]: t=(x-xs[j-1])/(xs[j]-xs[j-1]); return ys[j-1]+t*(ys[j]-ys[j-1])
    return ys[-1]
def lagrange(x,xs,ys):
    s=0
    for i in range(len(xs)):
        t=ys[i]
        for j in range(len(xs)):
            if j!=i: t*=(x-xs[j])/(xs[i]-xs[j])
        s+=t
    return s
def bd(r0,p0,r1,p1,N=400):
    l0=[math.log(r) for r in r0];l1=[math.log(r) for r in r1]
    lo=max(min(p0),min(p1));hi=min(max(p0),max(p1))
    xs=[lo+(hi-lo)*(k+0.5)/N for k in range(N)]
    cub=math.exp(mean([lagrange(x,p1,l1)-lagrange(x,p0,l0) for x in xs]))-1
    lin=math.exp(mean([interp(x,p1,l1)-interp(x,p0,l0) for x in xs]))-1
    return cub,lin
R={}
for m in ['nomodes','modes']:
    for q in Q: R[(m,q)]=load(q,m)
print('q  mode     stored   file   psnr  modes')
for q in Q:
  for m in ['nomodes','modes']:
    s,f,p,md=R[(m,q)]; print(q,m,sum(s),sum(f),'%.4f'%mean(p),md)
  s0=R[('nomodes',q)];s1=R[('modes',q)]
  print('   stored %+.3f%%  file %+.3f%%  dPSNR %+.4f'%(100*(sum(s1[0])/sum(s0[0])-1),100*(sum(s1[1])/sum(s0[1])-1),mean(s1[2])-mean(s0[2])))
for which,idx in [('stored',0),('file',1)]:
    g=lambda m,q:sum(R[(m,q)][idx]); pp=lambda m,q:mean(R[(m,q)][2])
    r0=[g('nomodes',q) for q in Q];p0=[pp('nomodes',q) for q in Q]
    r1=[g('modes',q) for q in Q];p1=[pp('modes',q) for q in Q]
    c,l=bd(r0,p0,r1,p1); print('BD-rate pooled (%s bytes): cubic %+.3f%%  piecewise-linear %+.3f%%'%(which,100*c,100*l))
    per=[]
    for k in range(len(imgs)):
        a=[R[('nomodes',q)][idx][k] for q in Q];b=[R[('nomodes',q)][2][k] for q in Q]
        c_=[R[('modes',q)][idx][k] for q in Q];d=[R[('modes',q)][2][k] for q in Q]
        per.append(100*bd(a,b,c_,d)[1])
    print('  per image (lin) mean %+.3f%% min %+.3f%% max %+.3f%% (%s)'%(mean(per),min(per),max(per),imgs[per.index(max(per))]))
    for q in Q:
        beyond = pp('modes',q) > max(p0)
        print('   q%d: modes bytes vs nomodes curve at equal PSNR %+.3f%%%s'%(q,100*(g('modes',q)/math.exp(interp(pp('modes',q),p0,[math.log(r) for r in r0]))-1),
              ' (PSNR beyond the curve: against its top point, not comparable)' if beyond else ''))
import re, collections
speed = collections.defaultdict(list)
for line in open(D + '/decode.txt'):
    m = re.match(r'\d (\d+) (\S+) .*decode ([\d.]+) Mtexel/s', line)
    speed[(int(m[1]), m[2])].append(float(m[3]))
for q in Q:
    a = sorted(speed[(q, 'nomodes')])[1]; b = sorted(speed[(q, 'modes')])[1]
    print('decode q%d: no-page-modes %s, modes %s Mtexel/s (medians %.1f / %.1f, %+.1f%%)'
          % (q, speed[(q, 'nomodes')], speed[(q, 'modes')], a, b, 100 * (b / a - 1)))
PY
