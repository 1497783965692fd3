import json,sys
a=json.load(open(sys.argv[1]));b=json.load(open(sys.argv[2]))
print("camera ate", a["camera"]["ate_m"], b["camera"]["ate_m"])
print("clust acc", a["clustering"]["accuracy"], b["clustering"]["accuracy"])
for k in ["ate_m","me_r_deg","me_t_m","matched"]:
    print("objects",k,a["objects"][k],b["objects"][k])
fa={o["gt_object"]:o for o in a["objects"]["per_object"] if o.get("found")}
fb={o["gt_object"]:o for o in b["objects"]["per_object"] if o.get("found")}
for g in sorted(set(fa)|set(fb)):
    print(g, *[ (round(fa[g][k],5) if g in fa else None, round(fb[g][k],5) if g in fb else None) for k in ["ate_m","me_r_deg","me_t_m"]])
