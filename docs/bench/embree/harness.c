/* Embree 3 reference timing on the shared PLRAYS1 files, for comparison with `plenum bench`
   in the same run: build with RTC_BUILD_QUALITY_HIGH (median of 5 after a warm-up), then
   rtcIntersect1 and rtcOccluded1 on 2 threads, each the median of 5 passes after a warm-up.
   Prints one JSON line, with the growth of the resident set over the first build per
   triangle (Embree's own copy of the geometry and its BVH, the vertex and index buffers,
   and whatever its allocator keeps: an upper bound on its memory per triangle).
   With `compact`, the scene is built with RTC_SCENE_FLAG_COMPACT: leaves refer to the
   vertex buffer by index instead of holding precomputed triangles, as Plenum's do.

     gcc -O2 -fopenmp harness.c -o embree-harness -lembree3
     ./embree-harness MESH.raw RAYS [compact]   (MESH.raw from dump_mesh.py) */
#include <embree3/rtcore.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include <omp.h>
static double now(void){struct timespec t;clock_gettime(CLOCK_MONOTONIC,&t);return t.tv_sec+t.tv_nsec*1e-9;}
static long resident_bytes(void){long pages=0,resident=0;FILE*f=fopen("/proc/self/statm","r");if(f){if(fscanf(f,"%ld %ld",&pages,&resident)!=2)resident=0;fclose(f);}return resident*4096;}
static int cmp(const void*a,const void*b){double x=*(double*)a,y=*(double*)b;return x<y?-1:x>y;}
typedef struct { float o[3], tmin, d[3], tmax; } R;
int main(int argc,char**argv){
  if(argc<3||argc>4||(argc==4&&strcmp(argv[3],"compact"))){fprintf(stderr,"usage: %s MESH.raw RAYS [compact]\n",argv[0]);return 2;}
  int compact=argc==4;
  FILE*f=fopen(argv[1],"rb"); if(!f){perror(argv[1]);return 2;} uint64_t nv,nt; fread(&nv,8,1,f); fread(&nt,8,1,f);
  float*v=malloc(nv*12); uint32_t*ix=malloc(nt*12); fread(v,4,nv*3,f); fread(ix,4,nt*3,f); fclose(f);
  f=fopen(argv[2],"rb"); if(!f){perror(argv[2]);return 2;} char mg[8]; uint64_t n; fread(mg,8,1,f); fread(&n,8,1,f); R*r=malloc(n*32); fread(r,32,n,f); fclose(f);
  int coherent=1; for(uint64_t i=1;i<n;i++) if(memcmp(r[i].o,r[0].o,12)){coherent=0;break;}
  RTCDevice dev=rtcNewDevice("threads=2");
  double tb[6]; RTCScene sc=0; long rss0=resident_bytes(),rss1=0;
  for(int p=0;p<6;p++){
    double t0=now();
    RTCGeometry g=rtcNewGeometry(dev,RTC_GEOMETRY_TYPE_TRIANGLE);
    float*vb=rtcSetNewGeometryBuffer(g,RTC_BUFFER_TYPE_VERTEX,0,RTC_FORMAT_FLOAT3,12,nv); memcpy(vb,v,nv*12);
    uint32_t*ib=rtcSetNewGeometryBuffer(g,RTC_BUFFER_TYPE_INDEX,0,RTC_FORMAT_UINT3,12,nt); memcpy(ib,ix,nt*12);
    rtcSetGeometryBuildQuality(g,RTC_BUILD_QUALITY_HIGH); rtcCommitGeometry(g);
    if(sc) rtcReleaseScene(sc);
    sc=rtcNewScene(dev); rtcSetSceneBuildQuality(sc,RTC_BUILD_QUALITY_HIGH); if(compact) rtcSetSceneFlags(sc,RTC_SCENE_FLAG_COMPACT);
    rtcAttachGeometry(sc,g); rtcReleaseGeometry(g); rtcCommitScene(sc);
    tb[p]=now()-t0; if(p==0) rss1=resident_bytes();
  }
  qsort(tb+1,5,8,cmp);
  double tc[6],ta[6]; long hits=0,occ=0;
  for(int q=0;q<2;q++) for(int p=0;p<6;p++){
    double t0=now(); long cnt=0;
    #pragma omp parallel for schedule(dynamic,1024) reduction(+:cnt) num_threads(2)
    for(long i=0;i<(long)n;i++){
      struct RTCIntersectContext ctx; rtcInitIntersectContext(&ctx); ctx.flags=coherent?RTC_INTERSECT_CONTEXT_FLAG_COHERENT:RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
      if(q==0){ struct RTCRayHit rh; rh.ray.org_x=r[i].o[0];rh.ray.org_y=r[i].o[1];rh.ray.org_z=r[i].o[2];rh.ray.tnear=r[i].tmin;
        rh.ray.dir_x=r[i].d[0];rh.ray.dir_y=r[i].d[1];rh.ray.dir_z=r[i].d[2];rh.ray.tfar=r[i].tmax;rh.ray.mask=-1;rh.ray.flags=0;rh.ray.time=0;
        rh.hit.geomID=RTC_INVALID_GEOMETRY_ID; rtcIntersect1(sc,&ctx,&rh); cnt+=rh.hit.geomID!=RTC_INVALID_GEOMETRY_ID; }
      else { struct RTCRay ry; ry.org_x=r[i].o[0];ry.org_y=r[i].o[1];ry.org_z=r[i].o[2];ry.tnear=r[i].tmin;
        ry.dir_x=r[i].d[0];ry.dir_y=r[i].d[1];ry.dir_z=r[i].d[2];ry.tfar=r[i].tmax;ry.mask=-1;ry.flags=0;ry.time=0;
        rtcOccluded1(sc,&ctx,&ry); cnt+=ry.tfar<0; }
    }
    double t=now()-t0; if(q==0){tc[p]=t;hits=cnt;} else {ta[p]=t;occ=cnt;}
  }
  qsort(tc+1,5,8,cmp); qsort(ta+1,5,8,cmp);
  printf("{\"build_ms\":%.1f,\"closest_mrays_per_s\":%.2f,\"any_mrays_per_s\":%.2f,\"hit_fraction\":%.4f,\"occluded_fraction\":%.4f,\"rss_bytes_per_tri\":%.1f}\n",
    tb[3]*1e3, n/tc[3]/1e6, n/ta[3]/1e6, (double)hits/n, (double)occ/n, (double)(rss1-rss0)/nt);
  return 0;
}
