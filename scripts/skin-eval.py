#!/usr/bin/python3
"""Error over a clip of a skinned proxy, as a host runs it: the .spx skinned with spx.skin at
every pose of a pose-extract --animation folder, per frame the median and max distance from the
mesh vertices to the union surface and the deepest vertex inside the union (% of the rest
diagonal), split into frames the chain saw (frame % EVERY == 0) and the others.
usage: skin-eval.py MODULE_DIR FILE.spx POSES_DIR EVERY"""
import sys, json, numpy as np
sys.path.insert(0, sys.argv[1]); import spx
p = spx.load(sys.argv[2]); folder = sys.argv[3]; every_seen = int(sys.argv[4])
skin = json.load(open(folder + '/skin.json')); man = json.load(open(folder + '/poses.json'))
def obj(f): return np.array([[float(x) for x in l.split()[1:4]] for l in open(f) if l.startswith('v ')])
R = obj(folder + '/rest.obj'); diag = np.linalg.norm(R.max(0)-R.min(0))
rows=[]
for k, pose in enumerate(man['poses']):
    M = np.array([np.array(m).reshape(4,4).T for m in skin['poses'][k]['joint_matrices']], dtype=np.float32)
    S = p.skin(M); V = obj(folder + '/' + pose['file'])
    e = (np.linalg.norm(V[:,None,:]-S[None,:,:3], axis=2) - S[None,:,3]).min(1)
    err = np.abs(e); over = max(0, -e.min())
    frame = pose['source']['frame']
    rows.append((frame, frame % every_seen == 0, np.median(err)/diag*100, err.max()/diag*100, over/diag*100))
print(f"{p.sphere_count} spheres")
for name, rs in (('seen', [r for r in rows if r[1]]), ('unseen', [r for r in rows if not r[1]])):
    a = np.array([r[2:] for r in rs])
    print(f"{name}: {len(rs)} frames, median error (median over frames) {np.median(a[:,0]):.2f}%, max error median {np.median(a[:,1]):.2f}%, worst {a[:,1].max():.2f}%, deepest body vertex inside the union {a[:,2].max():.3f}%")
