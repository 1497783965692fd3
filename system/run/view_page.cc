#include "system/run/view_page.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/options_reader.h"
#include "system/draw/cluster_colors.h"
#include "system/run/run_outputs_reader.h"

namespace cslam {

namespace fs = std::filesystem;

namespace {

std::string ReadWhole(const fs::path& file, const std::string& what) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "cannot read " + what);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Numbers to centimetres (positions) or 1e-4 (rotations): the page's size is mostly these.
void Num(std::string& out, double v, int decimals) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  std::string s(buf);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  out += s;
  out += ',';
}

void Close(std::string& out, char bracket) {
  if (!out.empty() && out.back() == ',') out.pop_back();
  out += bracket;
}

void Pose12(std::string& out, const Pose& p) {
  const Eigen::Matrix<double, 3, 4> m = p.matrix().topRows<3>();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) Num(out, m(r, c), c == 3 ? 3 : 5);
}

std::string Hex(const cv::Vec3b& rgb) {
  char buf[8];
  std::snprintf(buf, sizeof(buf), "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
  return buf;
}

std::string IntList(const std::vector<int>& v) {
  std::string s = "[";
  for (int x : v) s += std::to_string(x) + ",";
  Close(s, ']');
  return s;
}

// The data of the page with the static and outlier points thinned to every `every`-th.
std::string RunData(const RunOutputs& o, const nlohmann::json& metrics, int every, int* kept,
                    int* thinnable) {
  std::string d = "{\"frames\":" + IntList(o.camera.frames) + ",\"cam\":[";
  for (const Pose& p : o.camera.poses) Pose12(d, p);
  Close(d, ']');
  d += ",\"gtcam\":[";
  for (const Pose& p : o.gt_camera.poses)
    for (int i = 0; i < 3; ++i) Num(d, p.translation()(i), 2);
  Close(d, ']');
  d += ",\"colors\":{\"static\":\"" + Hex(ColorForCluster(0)) + "\",\"outlier\":\"" +
       Hex(ColorForCluster(-1)) + "\"}";

  // Points: static/outliers in the world, an object's in its own frame (placed per frame).
  std::string xyz = "[", cl = "[", f0 = "[", f1 = "[";
  std::map<int, int> counts;
  *kept = *thinnable = 0;
  for (const RunLandmark& l : o.landmarks) {
    Eigen::Vector3d p = l.p_world;
    if (l.cluster >= 1) {
      const auto c = o.clusters.find(l.cluster);
      if (c == o.clusters.end()) continue;
      const int k = PlacingPoseIndex(c->second, l.last_frame);
      if (k < 0) continue;
      p = c->second.poses[k].inverse() * l.p_world;
      ++counts[l.cluster];
    } else if ((*thinnable)++ % every != 0) {
      continue;
    } else {
      ++*kept;
    }
    for (int i = 0; i < 3; ++i) Num(xyz, p(i), 2);
    cl += std::to_string(l.cluster) + ",";
    f0 += std::to_string(l.first_frame) + ",";
    f1 += std::to_string(l.last_frame) + ",";
  }
  Close(xyz, ']'), Close(cl, ']'), Close(f0, ']'), Close(f1, ']');
  d += ",\"pts\":{\"xyz\":" + xyz + ",\"c\":" + cl + ",\"f0\":" + f0 + ",\"f1\":" + f1 + "}";

  std::map<int, nlohmann::json> object_metrics;
  if (metrics.contains("objects") && metrics["objects"].contains("per_object"))
    for (const auto& po : metrics["objects"]["per_object"])
      if (po.contains("cluster") && po["cluster"].is_number_integer())
        object_metrics[po["cluster"].get<int>()] = po;
  const std::map<int, ClusterCentroid> centroids = ClusterCentroids(o);
  d += ",\"objects\":[";
  for (const auto& [id, t] : o.clusters) {
    const auto c = centroids.find(id);
    const Eigen::Vector3d centroid = c == centroids.end() ? Eigen::Vector3d::Zero() : c->second.p;
    d += "{\"id\":" + std::to_string(id) + ",\"color\":\"" + Hex(ColorForCluster(id)) +
         "\",\"landmarks\":" + std::to_string(counts[id]) + ",\"frames\":" + IntList(t.frames) +
         ",\"poses\":[";
    for (const Pose& p : t.poses) Pose12(d, p);
    Close(d, ']');
    d += ",\"track\":[";
    for (const Pose& p : t.poses)
      for (int i = 0; i < 3; ++i) Num(d, (p * centroid)(i), 2);
    Close(d, ']');
    const auto m = object_metrics.find(id);
    d += ",\"metrics\":" + (m == object_metrics.end() ? std::string("null") : m->second.dump()) + "},";
  }
  Close(d, ']');
  d += ",\"gt\":[";
  for (const auto& [id, t] : o.gt_objects) {
    const auto match = o.gt_object_match.find(id);
    const int cluster = match == o.gt_object_match.end() ? -1 : match->second.second;
    const std::string type = match == o.gt_object_match.end() ? "object" : match->second.first;
    d += "{\"id\":" + std::to_string(id) + ",\"type\":" + nlohmann::json(type).dump() +
         ",\"cluster\":" + std::to_string(cluster) + ",\"color\":\"" +
         Hex(cluster >= 1 ? ColorForCluster(cluster) : TrajectoryColor(kUndrawnClusters)) +
         "\",\"frames\":" + IntList(t.frames) + ",\"pos\":[";
    for (const Pose& p : t.poses)
      for (int i = 0; i < 3; ++i) Num(d, p.translation()(i), 2);
    Close(d, ']');
    d += "},";
  }
  Close(d, ']');
  d += ",\"thin\":{\"every\":" + std::to_string(every) + ",\"kept\":" + std::to_string(*kept) +
       ",\"total\":" + std::to_string(*thinnable) + "}}";
  return d;
}

// The page around the data: panels, the scene, the slider, layers, picking, the state report.
constexpr const char* kPageHead = R"HTML(<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>%TITLE%</title>
<style>
body{margin:0;overflow:hidden;font:13px sans-serif;background:#fff}
#panel{position:absolute;top:8px;left:8px;background:rgba(255,255,255,.92);border:1px solid #999;padding:8px;max-width:360px}
#info{position:absolute;bottom:8px;left:8px;background:rgba(255,255,255,.92);border:1px solid #999;padding:8px;white-space:pre;font:12px monospace;min-width:200px}
#slider{width:300px}
#state{display:none}
.sw{display:inline-block;width:10px;height:10px;margin-right:4px;border-radius:5px}
</style></head><body>
<div id="panel"><b>%TITLE%</b><br>
<input type="range" id="slider" min="0" value="0"> <button id="play">play</button><br>
<span id="label"></span><br><span id="thin"></span>
<div id="layers"></div></div>
<div id="info">click an object's points</div>
<pre id="state"></pre>
<script>
window.cslamErrors=[];
window.onerror=function(m,s,l){window.cslamErrors.push(String(m)+' (line '+l+')');var e=document.getElementById('state');if(e)e.textContent=JSON.stringify({errors:window.cslamErrors});};
</script>
)HTML";

constexpr const char* kPageScript = R"JS(
(function(){
var D=window.RUN;
var W=window.innerWidth,H=window.innerHeight;
var renderer=new THREE.WebGLRenderer({antialias:true,preserveDrawingBuffer:true});
renderer.setSize(W,H);renderer.setClearColor(0xffffff);
document.body.appendChild(renderer.domElement);
var scene=new THREE.Scene();
var camera=new THREE.PerspectiveCamera(55,W/H,0.1,5000);
camera.up.set(0,-1,0);
var controls=new THREE.OrbitControls(camera,renderer.domElement);
function mat(a,i){var m=new THREE.Matrix4();m.set(a[i],a[i+1],a[i+2],a[i+3],a[i+4],a[i+5],a[i+6],a[i+7],a[i+8],a[i+9],a[i+10],a[i+11],0,0,0,1);return m;}
function line(flat,color,dashed){var g=new THREE.BufferGeometry();g.setAttribute('position',new THREE.Float32BufferAttribute(flat,3));
 var m=dashed?new THREE.LineDashedMaterial({color:color,dashSize:0.8,gapSize:0.6}):new THREE.LineBasicMaterial({color:color});
 var l=new THREE.Line(g,m);if(dashed)l.computeLineDistances();return l;}
var vs='uniform float frame;uniform float size;attribute float f0;attribute float f1;attribute vec3 rgb;varying vec3 vc;varying float seen;'+
 'void main(){seen=(frame>=f0&&frame<=f1)?1.0:0.0;vc=rgb;vec4 mv=modelViewMatrix*vec4(position,1.0);'+
 'gl_PointSize=clamp(size*(seen>0.5?1.8:1.0)*60.0/max(-mv.z,0.1),1.5,12.0);gl_Position=projectionMatrix*mv;}';
var fs='varying vec3 vc;varying float seen;void main(){gl_FragColor=vec4(mix(vc*0.35+0.65,vc,seen),1.0);}';
var frameUniform={value:0};
function points(idx,color){var n=idx.length,p=new Float32Array(3*n),a=new Float32Array(n),b=new Float32Array(n),c=new Float32Array(3*n);
 var col=new THREE.Color(color);
 for(var k=0;k<n;k++){var i=idx[k];p[3*k]=D.pts.xyz[3*i];p[3*k+1]=D.pts.xyz[3*i+1];p[3*k+2]=D.pts.xyz[3*i+2];a[k]=D.pts.f0[i];b[k]=D.pts.f1[i];c[3*k]=col.r;c[3*k+1]=col.g;c[3*k+2]=col.b;}
 var g=new THREE.BufferGeometry();g.setAttribute('position',new THREE.BufferAttribute(p,3));g.setAttribute('f0',new THREE.BufferAttribute(a,1));
 g.setAttribute('f1',new THREE.BufferAttribute(b,1));g.setAttribute('rgb',new THREE.BufferAttribute(c,3));
 var m=new THREE.ShaderMaterial({uniforms:{frame:frameUniform,size:{value:3.0}},vertexShader:vs,fragmentShader:fs});
 var o=new THREE.Points(g,m);o.userData.count=n;return o;}
var byCluster={};
for(var i=0;i<D.pts.c.length;i++){var c=D.pts.c[i];(byCluster[c]=byCluster[c]||[]).push(i);}
var layers=[];
function layer(name,color,objs){var L={name:name,color:color,objs:objs,on:true};objs.forEach(function(o){scene.add(o);});layers.push(L);return L;}
var staticL=layer('static points',D.colors.static,[points(byCluster[0]||[],D.colors.static)]);
var outL=layer('outliers',D.colors.outlier,[points(byCluster[-1]||[],D.colors.outlier)]);
var camFlat=[];for(var k=0;k<D.frames.length;k++){camFlat.push(D.cam[12*k+3],D.cam[12*k+7],D.cam[12*k+11]);}
var camPath=line(camFlat,0x000000,false);scene.add(camPath);
var fr=new THREE.BufferGeometry();var d=2.0,w=1.6,h=0.6;
fr.setAttribute('position',new THREE.Float32BufferAttribute([0,0,0,-w,-h,d,0,0,0,w,-h,d,0,0,0,w,h,d,0,0,0,-w,h,d,-w,-h,d,w,-h,d,w,-h,d,w,h,d,w,h,d,-w,h,d,-w,h,d,-w,-h,d],3));
var frustum=new THREE.LineSegments(fr,new THREE.LineBasicMaterial({color:0x000000}));frustum.matrixAutoUpdate=false;scene.add(frustum);
var gtObjs=[];if(D.gtcam.length)gtObjs.push(line(D.gtcam,0x000000,true));
D.gt.forEach(function(g){if(g.pos.length>=6)gtObjs.push(line(g.pos,g.color,true));});
var gtL=layer('ground truth (dashed)','#000000',gtObjs);
var objects=D.objects.map(function(o){
 var pts=points(byCluster[o.id]||[],o.color);pts.matrixAutoUpdate=false;pts.userData.object=o;
 var track=line(o.track,o.color,false);
 var axes=new THREE.AxesHelper(1.5);axes.matrixAutoUpdate=false;
 var idx={};o.frames.forEach(function(f,k){idx[f]=k;});o.index=idx;
 o.points=pts;o.axes=axes;o.layer=layer('object '+o.id+' ('+o.landmarks+' points)',o.color,[pts,track,axes]);return o;});
var lay=document.getElementById('layers');
layers.forEach(function(L){var lab=document.createElement('label');var cb=document.createElement('input');cb.type='checkbox';cb.checked=true;
 cb.onchange=function(){L.on=cb.checked;update();};lab.appendChild(cb);var sw=document.createElement('span');sw.className='sw';sw.style.background=L.color;
 lab.appendChild(sw);lab.appendChild(document.createTextNode(L.name));lay.appendChild(lab);lay.appendChild(document.createElement('br'));});
var thin=document.getElementById('thin');
if(D.thin.every>1)thin.textContent='static points thinned to every '+D.thin.every+'th: '+D.thin.kept+' of '+D.thin.total+' shown (page size limit)';
var slider=document.getElementById('slider');slider.max=D.frames.length-1;
var cur=0,shown={},selected=null,hookLog=[];
function frameIndex(want){var k=0;while(k<D.frames.length-1&&D.frames[k]<want)k++;return k;}
function visibleObjects(f){return objects.filter(function(o){return o.layer.on&&o.index[f]!==undefined;});}
function update(){
 var f=D.frames[cur];frameUniform.value=f;
 frustum.matrix.copy(mat(D.cam,12*cur));frustum.matrixWorldNeedsUpdate=true;
 layers.forEach(function(L){L.objs.forEach(function(o){o.visible=L.on;});});
 var drawn=0;
 if(staticL.on)drawn+=staticL.objs[0].userData.count;if(outL.on)drawn+=outL.objs[0].userData.count;
 objects.forEach(function(o){var k=o.index[f];o.points.visible=o.axes.visible=o.layer.on&&k!==undefined;
  if(k!==undefined){o.points.matrix.copy(mat(o.poses,12*k));o.points.matrixWorldNeedsUpdate=true;
   o.axes.matrix.copy(o.points.matrix);o.axes.matrixWorldNeedsUpdate=true;}
  if(o.points.visible)drawn+=o.points.userData.count;});
 var vis=visibleObjects(f).map(function(o){return o.id;});
 document.getElementById('label').textContent='frame '+f+' ('+(cur+1)+' of '+D.frames.length+'), objects in view: '+(vis.length?vis.join(', '):'none');
 slider.value=cur;
 shown={frame:f,points_drawn:drawn,objects_visible:vis};report();
}
function report(){document.getElementById('state').textContent=JSON.stringify({frame:shown.frame,points_drawn:shown.points_drawn,
 objects_visible:shown.objects_visible,selected:selected,hooks:hookLog,errors:window.cslamErrors});}
slider.oninput=function(){cur=parseInt(slider.value);update();};
var timer=null;
document.getElementById('play').onclick=function(){var b=this;if(timer){clearInterval(timer);timer=null;b.textContent='play';return;}
 b.textContent='pause';timer=setInterval(function(){if(cur>=D.frames.length-1){clearInterval(timer);timer=null;b.textContent='play';return;}cur++;update();},100);};
var ray=new THREE.Raycaster();ray.params.Points.threshold=0.5;
renderer.domElement.addEventListener('click',function(e){
 var m=new THREE.Vector2(e.clientX/W*2-1,-e.clientY/H*2+1);ray.setFromCamera(m,camera);
 var hits=ray.intersectObjects(objects.filter(function(o){return o.points.visible;}).map(function(o){return o.points;}));
 var info=document.getElementById('info');
 if(!hits.length){info.textContent='click an object\'s points';selected=null;report();return;}
 var o=hits[0].object.userData.object;selected=o.id;var t='object '+o.id+'\nframes '+o.frames[0]+'-'+o.frames[o.frames.length-1]+' ('+o.frames.length+' poses)\nlandmarks '+o.landmarks;
 D.gt.forEach(function(g){if(g.cluster===o.id)t+='\nground truth: id '+g.id+' ('+g.type+')';});
 if(o.metrics){for(var k in o.metrics){if(k!=='cluster')t+='\n'+k+': '+(typeof o.metrics[k]==='number'?+o.metrics[k].toFixed(3):o.metrics[k]);}}
 else t+='\nno metrics (no labelled object matched)';
 info.textContent=t;report();});
// The view: above and behind the middle of the camera's path, looking at it.
var box=new THREE.Box3().setFromBufferAttribute(camPath.geometry.getAttribute('position'));
var centre=box.getCenter(new THREE.Vector3()),size=Math.max(20,box.getSize(new THREE.Vector3()).length());
camera.position.set(centre.x,centre.y-0.7*size,centre.z-0.6*size);controls.target.copy(centre);controls.update();
// The URL fragment: frame=N opens the page at frame N. slide=N and click=ID drive the real
// controls through their own event handlers, for the browser test and for links to a view:
// slide=N moves the slider to frame N and fires its input event; click=ID sends a click to
// the canvas at the pixel of object ID's point nearest the viewer among those no panel covers,
// so the page's own picking (a ray through that pixel) has to find the object.
var hooks={};window.location.hash.replace(/^#/,'').split('&').forEach(function(kv){var p=kv.split('=');if(p.length===2)hooks[p[0]]=p[1];});
if(hooks.frame!==undefined)cur=frameIndex(parseInt(hooks.frame));
update();
function slideTo(f){hookLog.push('slide '+f);slider.value=frameIndex(f);slider.dispatchEvent(new Event('input',{bubbles:true}));}
function clickObject(id){
 var o=objects.filter(function(x){return x.id===id;})[0];
 if(!o||!o.points.visible){hookLog.push('click '+id+': not in view at frame '+D.frames[cur]);report();return;}
 var pos=o.points.geometry.getAttribute('position'),v=new THREE.Vector3(),best=null,bestD=Infinity;
 for(var i=0;i<pos.count;i++){v.fromBufferAttribute(pos,i).applyMatrix4(o.points.matrixWorld);var d=v.distanceTo(camera.position);
  var s=v.clone().project(camera);var x=(s.x+1)/2*W,y=(1-s.y)/2*H;
  if(d>=bestD||s.z>1||x<1||y<1||x>W-2||y>H-2||document.elementFromPoint(x,y)!==renderer.domElement)continue;
  bestD=d;best={x:x,y:y};}
 if(!best){hookLog.push('click '+id+': no point of it on screen');report();return;}
 var at=document.elementFromPoint(best.x,best.y);hookLog.push('click '+id+' at '+Math.round(best.x)+','+Math.round(best.y));
 at.dispatchEvent(new MouseEvent('click',{clientX:best.x,clientY:best.y,bubbles:true,cancelable:true,view:window}));}
// One step per drawn frame, so each acts on what the one before it showed.
var steps=[];
if(hooks.slide!==undefined)steps.push(function(){slideTo(parseInt(hooks.slide));});
if(hooks.click!==undefined)steps.push(function(){clickObject(parseInt(hooks.click));});
function animate(){requestAnimationFrame(animate);renderer.render(scene,camera);var s=steps.shift();if(s)s();}
animate();
})();
</script></body></html>
)JS";

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

}  // namespace

void ViewPageOptions::Check() const {
  CheckOption(max_bytes >= 1024 * 1024, "view.max_bytes", "must be >= 1 MiB", max_bytes);
}

std::string BuildViewPage(const RunOutputs& outputs, const std::string& metrics_json,
                          const ViewPageOptions& options) {
  options.Check();
  const fs::path dir(options.three_js_dir);
  const std::string three = ReadWhole(dir / "three.min.js", "three.js (Debian package libjs-three)");
  const std::string orbit =
      ReadWhole(dir / "examples" / "js" / "controls" / "OrbitControls.js", "three.js's OrbitControls (Debian package libjs-three)");
  nlohmann::json metrics;
  if (!metrics_json.empty()) metrics = nlohmann::json::parse(metrics_json, nullptr, false);
  if (metrics.is_discarded()) metrics = nlohmann::json::object();
  std::string title = Replace(Replace(options.title, "&", "&amp;"), "<", "&lt;");
  const std::string head = Replace(kPageHead, "%TITLE%", title);
  // "</script" inside the inlined library would end its element early.
  const std::string library = Replace(three + "\n" + orbit, "</script", "<\\/script");
  const long long fixed = static_cast<long long>(head.size() + library.size()) + 2000 +
                          static_cast<long long>(std::char_traits<char>::length(kPageScript));
  int kept = 0, total = 0;
  for (int every = 1;; every *= 2) {
    const std::string data = RunData(outputs, metrics, every, &kept, &total);
    if (fixed + static_cast<long long>(data.size()) <= options.max_bytes) {
      return head + "<script>\n" + library + "\n</script>\n<script>window.RUN=" + data +
             ";</script>\n<script>" + kPageScript;
    }
    if (kept == 0)
      throw OutputError("view.html", "the objects alone need more than " +
                                         std::to_string(options.max_bytes) + " bytes");
  }
}

std::string WriteViewPage(const RunOutputs& outputs, const std::string& out_dir,
                          const ViewPageOptions& options) {
  const fs::path metrics = fs::path(out_dir) / "metrics.json";
  std::string metrics_json;
  std::error_code ec;
  if (fs::exists(metrics, ec)) metrics_json = ReadWhole(metrics, "metrics.json");
  ViewPageOptions o = options;
  if (o.title == ViewPageOptions{}.title) o.title = "cslam run " + fs::path(out_dir).filename().string();
  const std::string page = BuildViewPage(outputs, metrics_json, o);
  const std::string path = (fs::path(out_dir) / "view.html").string();
  WriteFileAtomically(path, [&](std::ostream& s) { s << page; });
  return path;
}

std::string WriteViewPage(const std::string& out_dir, const ViewPageOptions& options) {
  return WriteViewPage(ReadRunOutputs(out_dir), out_dir, options);
}

}  // namespace cslam
