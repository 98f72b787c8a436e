#!/usr/bin/env python3
"""Write small synthetic Nanosurf .nid, PicoView .mi, WSxM .top and NT-MDT .mdt
files covering the layout variants the readers claim (sample types, units,
frame types, header omissions), into the folder given (default: here).
Gwyddion 2.62's reading of each is in gwyddion/ (dump.sh): the tests compare
sunbeam-afm with it (crates/sunbeam-afm/tests/instruments.rs)."""
import os, struct, sys

os.chdir(sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__)))
def wsxm(name, dtype='short', chan='Topography', zamp='10 nm', xamp='600 nm', yamp='300 nm', xdir='Forward', ydir='Up', cols=4, rows=3, vals=None, extra=''):
    if vals is None: vals=[(i*7)%11 - 3 for i in range(cols*rows)]
    code={'short':'h','integer':'i','float':'f','double':'d','unsigned char':'B'}[dtype]
    data=struct.pack('<%d%s'%(len(vals),code),*vals)
    def hdr(hs):
        s='WSxM file copyright Nanotec Electronica\r\nSxM Image file\r\nImage header size: %d\r\n\r\n'%hs
        s+='[Control]\r\n\r\n'
        if xamp: s+='    X Amplitude: %s\r\n'%xamp
        if yamp: s+='    Y Amplitude: %s\r\n'%yamp
        s+='\r\n[General Info]\r\n\r\n'
        if chan: s+='    Acquisition channel: %s\r\n'%chan
        s+='    Image Data Type: %s\r\n    Number of columns: %d\r\n    Number of rows: %d\r\n'%(dtype,cols,rows)
        s+='    X scanning direction: %s\r\n    Y scanning direction: %s\r\n'%(xdir,ydir)
        if zamp: s+='    Z Amplitude: %s\r\n'%zamp
        s+=extra
        s+='\r\n[Header end]\r\n'
        return s
    hs=len(hdr(0)); hs=len(hdr(hs)); h=hdr(hs)
    assert len(h)==hs
    open(name,'wb').write(h.encode('latin1')+data)
wsxm('w_short.top')
wsxm('w_int.top', dtype='integer')
wsxm('w_float.top', dtype='float')
wsxm('w_double.top', dtype='double')
wsxm('w_uchar.top', dtype='unsigned char', vals=[(i*7)%11 for i in range(12)])
wsxm('w_down.top', ydir='Down')
wsxm('w_back.top', xdir='Backward')
wsxm('w_chan.top', chan='Amplitude', zamp='2 V')
wsxm('w_au.top', zamp='5 a.u.')
wsxm('w_nozamp.top', zamp=None)
wsxm('w_noxamp.top', xamp=None)
wsxm('w_noyamp.top', yamp=None)
wsxm('w_flat.top', vals=[5]*12)
wsxm('w_nochan.top', chan=None)
wsxm('w_um.top', zamp='1.5 \xb5m', xamp='2 \xb5m', yamp='3 \xc5')
wsxm('w_phase.top', chan='Phase', zamp='30 \xba')
for i,u in enumerate(['3 nA','3 A','3 Hz','3 deg','3 N','3','3 pm','3 mV']):
    wsxm('u_%d.top'%i, zamp=u, chan='Height')
def nid(name, bits=16, sign='Signed', frame='Scan forward', zunit='m', zname='Topography', xres=4, yres=3, groups=None, order='Intel', extra_ds=''):
    code={8:'b',16:'h',32:'i'}[bits]
    if sign!='Signed': code=code.upper()
    if groups is None: groups=[[('DataSet-0:1',frame,zname,zunit)]]
    s='[DataSet]\r\nVersion=2\r\nGroupCount=%d\r\n'%len(groups)
    secs=''
    data=b''
    k=0
    for gi,g in enumerate(groups):
        s+='Gr%d-Name=%s\r\nGr%d-ID=0\r\nGr%d-Count=%d\r\n'%(gi,'x',gi,gi,len(g)+1)
        for ci,(sec,fr,zn,zu) in enumerate(g):
            s+='Gr%d-Ch%d=%s\r\n'%(gi,ci+1,sec)
            secs+='[%s]\r\nVersion=2\r\nPoints=%d\r\nLines=%d\r\n'%(sec,xres,yres)
            if fr: secs+='Frame=%s\r\n'%fr
            secs+='Dim0Name=X*\r\nDim0Unit=um\r\nDim0Range=20\r\nDim0Min=0\r\nDim1Name=Y*\r\nDim1Unit=um\r\nDim1Range=10\r\nDim1Min=0\r\n'
            if zn: secs+='Dim2Name=%s\r\n'%zn
            if zu is not None: secs+='Dim2Unit=%s\r\n'%zu
            secs+='Dim2Range=1e-06\r\nDim2Min=-5e-07\r\nSaveMode=Binary\r\nSaveBits=%d\r\nSaveSign=%s\r\nSaveOrder=%s\r\n\r\n'%(bits,sign,order)
            n=xres*yres
            if sign=='Signed':
                vals=[((i*37+k*11)%(2**bits))-2**(bits-1) for i in range(n)]
                vals[0]=-2**(bits-1); vals[1]=2**(bits-1)-1
            else:
                vals=[((i*37+k*11)%(2**bits)) for i in range(n)]
            data+=struct.pack('<%d%s'%(n,code),*vals)
            k+=1
    s+=extra_ds+'\r\n'
    open(name,'wb').write((s+secs).encode('latin1')+b'#!'+data)
nid('n_16.nid')
nid('n_8.nid',bits=8)
nid('n_32.nid',bits=32)
nid('n_unsigned.nid',sign='Unsigned')
nid('n_noframe.nid',frame=None)
nid('n_nounit.nid',zunit=None)
nid('n_nozname.nid',zname=None)
nid('n_nm.nid',zunit='nm')
nid('n_deg.nid',zunit='\xb0',zname='Phase')
nid('n_motorola.nid',order='Motorola')
nid('n_two.nid',groups=[[('DataSet-0:1','Scan forward','Z','m'),('DataSet-0:2','Scan forward','Amp','V')],[('DataSet-1:1','Scan backward','Z','m')]])
nid('n_1d.nid',yres=1)
def kv(k,v): return (k.ljust(14)+v)
def mi(name, datatag='BINARY', bufs=None, xres=4, yres=3, xlen='2.0e-005', ylen='1.0e-005', scanup='TRUE', spect=False, eol='\n'):
    if bufs is None: bufs=[('Topography','um','2.5'),('Deflection','V','10')]
    lines=[kv('fileType','Spectroscopy' if spect else 'Image'), kv('version','PicoView 0x10c04'), kv('xPixels',str(xres)), kv('yPixels',str(yres))]
    if xlen: lines.append(kv('xLength',xlen))
    if ylen: lines.append(kv('yLength',ylen))
    lines.append(kv('scanUp',scanup))
    for lab,u,r in bufs:
        lines.append(kv('bufferLabel',lab))
        lines.append(kv('direction','Trace'))
        if r is not None: lines.append(kv('bufferRange',r))
        if u is not None: lines.append(kv('bufferUnit',u))
        lines.append(kv('trace','Trace'))
    lines.append(kv('data',datatag))
    h=eol.join(lines)+eol
    bits=32 if datatag=='BINARY_32' else 16
    code='i' if bits==32 else 'h'
    data=b''
    n=xres*yres
    for k in range(len(bufs)):
        vals=[((i*37+k*11)%(2**bits))-2**(bits-1) for i in range(n)]
        data+=struct.pack('<%d%s'%(n,code),*vals)
    open(name,'wb').write(h.encode('latin1')+data)
mi('m_16.mi')
mi('m_32.mi',datatag='BINARY_32')
mi('m_none.mi',datatag='')
mi('m_down.mi',scanup='FALSE')
mi('m_norange.mi',bufs=[('Topography','um',None)])
mi('m_nounit.mi',bufs=[('Topography',None,'2.5')])
mi('m_nolen.mi',xlen=None)
mi('m_crlf.mi',eol='\r\n')
mi('m_ascii.mi',datatag='ASCII')
mi('m_nm.mi',bufs=[('Height','nm','100')])
def frame_hdr(size, typ, var_size):
    return struct.pack('<IHBB6HH', size, typ, 7, 3, 2024, 1, 2, 3, 4, 5, var_size)
def scanned(xres=4, yres=3, xunit=-1, zunit=-1, xstep=5.0, ystep=-2.5, xoff=1.0, zoff=0.5, zstep=0.25, title=b'Height', ndots=0, var_size=107, typ=0):
    v=struct.pack('<ffh', xoff, xstep, xunit)+struct.pack('<ffh', 0.0, ystep, xunit)+struct.pack('<ffh', zoff, zstep, zunit)
    v+=struct.pack('<BBHHHfHBBBBBBfffBBiiB', 0, 1, xres, yres, 0, 1.0, 0, 0, 0, 0, 0, 0, 0, 1.0, 1.0, 1.0, 0, 0, 0, 0, 0)
    v=v.ljust(var_size, b'\0')
    fm=struct.pack('<4H', 0, xres, yres, ndots)
    dots=b''
    if ndots: dots=b'\0'*(14+16*ndots)
    n=xres*yres
    img=struct.pack('<%dh'%n, *[((i*37)%65536)-32768 if i>1 else (-32768 if i==0 else 32767) for i in range(n)])
    tail=b''
    if title is not None: tail=struct.pack('<I',len(title))+title
    body=v+fm+dots+img+tail
    return frame_hdr(22+len(body), typ, var_size)+body
def mda(xres=4, yres=3, dtype=-2, unit_z=b'nm', unit_xy=b'um', si_z=0, title=b'Topo', xscale=0.5, yscale=0.25, zscale=2.0, zbias=1.0):
    head=struct.pack('<II',76,0)+b'\0'*36+struct.pack('<8I',len(title),0,0,0,0,0,0,0)
    head=head.ljust(76,b'\0')
    ndim,nmes=2,1
    st=struct.pack('<QIII', xres*yres, 2, ndim, nmes)
    arr=struct.pack('<II', 0, len(st))+st
    def cal(name, unit, si, bias, scale, mn, mx, dt):
        s=struct.pack('<III', len(name), 0, len(unit))+struct.pack('<Qd', si, 0.0)+b'\0'*8+struct.pack('<dd', bias, scale)+struct.pack('<QQ', mn, mx)+struct.pack('<iI', dt, 0)
        body=struct.pack('<I', len(s))+s+name+unit
        return struct.pack('<I', 4+len(body))+body
    cals=cal(b'x',unit_xy,0,0.0,xscale,0,xres-1,0)+cal(b'y',unit_xy,0,0.0,yscale,0,yres-1,0)+cal(b'z',unit_z,si_z,zbias,zscale,0,0,dtype)
    n=xres*yres
    code={-1:'b',1:'B',-2:'h',2:'H',-4:'i',4:'I',-8:'q',8:'Q',-(4+23*256):'f',-(8+52*256):'d'}[dtype]
    vals=[(i*37)%100-50 for i in range(n)]
    if code.isupper(): vals=[abs(x) for x in vals]
    img=struct.pack('<%d%s'%(n,code), *vals)
    body=head+title+arr+cals+img
    return frame_hdr(22+len(body), 106, 0)+body
def mdt(name, frames):
    body=b''.join(frames)
    hdr=b'\x01\xb0\x93\xff'+struct.pack('<I', len(body))+b'\0'*4+struct.pack('<H', len(frames)-1)+b'\0'*18+b'\0'
    assert len(hdr)==33
    open(name,'wb').write(hdr+body)
mdt('t_scan.mdt',[scanned()])
mdt('t_scan_units.mdt',[scanned(xunit=-2, zunit=24, title=None)])
mdt('t_scan_dots.mdt',[scanned(ndots=2, zunit=2, title='Высота'.encode('cp1251'))])
mdt('t_mda16.mdt',[mda()])
mdt('t_mda_si.mdt',[mda(unit_z=b'', si_z=0x0000000000100001, dtype=-4)])
mdt('t_mda_f32.mdt',[mda(dtype=-(4+23*256), unit_z=b'V')])
mdt('t_mda_u8.mdt',[mda(dtype=1, unit_z=b'deg')])
mdt('t_mix.mdt',[scanned(title=b'A'), mda(title=b'B'), scanned(typ=1, title=b'spec'), scanned(title=b'C')])
def mda2(name_z, unit_z, si_z):
    xres,yres=4,3
    title=b'T'
    head=struct.pack('<II',76,0)+b'\0'*36+struct.pack('<8I',len(title),0,0,0,0,0,0,0)
    st=struct.pack('<QIII', xres*yres, 2, 2, 1)
    arr=struct.pack('<II', 0, len(st))+st
    def cal(name, unit, si, bias, scale, mn, mx, dt):
        s=struct.pack('<III', len(name), 0, len(unit))+struct.pack('<Qd', si, 0.0)+b'\0'*8+struct.pack('<dd', bias, scale)+struct.pack('<QQ', mn, mx)+struct.pack('<iI', dt, 0)
        body=struct.pack('<I', len(s))+s+name+unit
        return struct.pack('<I', 4+len(body))+body
    cals=cal(b'',b'',0x101,0.0,1e-6,0,xres-1,0)+cal(b'',b'',0x101,0.0,1e-6,0,yres-1,0)+cal(name_z,unit_z,si_z,0.0,1.0,0,0,-2)
    img=struct.pack('<12h',*range(12))
    body=head+title+arr+cals+img
    return frame_hdr(22+len(body), 106, 0)+body
mdt('s_empty_si.mdt',[mda2(b'',b'',0x100001)])
mdt('s_name_nA.mdt',[mda2(b'nA',b'',0x1)])
mdt('s_volt.mdt',[mda2(b'',b'',0xfffd010200)])
