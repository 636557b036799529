/PROG  DEBURR
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "deburring, two fixtures";
PROG_SIZE	= 2410;
CREATE		= DATE 24-03-04  TIME 07:12:40;
MODIFIED	= DATE 24-03-11  TIME 15:02:18;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 25;
MEMORY_SIZE	= 2880;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  !Deburring cell: two fixtures ;
   2:  !UF1 fixture A, UF2 fixture B ;
   3:  UFRAME_NUM=1 ;
   4:  UTOOL_NUM=1 ;
   5:J P[1:HOME] 30% FINE    ;
   6:J P[2:above A] 80% CNT100 ACC80    ;
   7:L P[3:edge A1] 400mm/sec CNT50 TB    .10sec,DO[12:spindle]=ON    ;
   8:L P[4:edge A2] 150mm/sec CNT20 PTH    ;
   9:C P[5:arc via]    
    :  P[6:arc end] 150mm/sec CNT10    ;
  10:A P[6:arc end] 120mm/sec CNT100    ;
  11:A P[7:arc 2] 120mm/sec CNT100    ;
  12:A P[8:arc 3] 120mm/sec FINE    ;
  13:L P[9:leave A] 1000mm/sec CNT100 ACC60 Skip,LBL[90]    
    :  TA   0.00sec,DO[12:spindle]=OFF    ;
  14:  //L P[4:edge A2] 150mm/sec FINE    ;
  15:  UFRAME_NUM=2 ;
  16:  UTOOL_NUM=2 ;
  17:J P[10:above B] 80% CNT100 Wjnt    ;
  18:L P[11:edge B1] 300mm/sec CNT30 Offset,PR[5:fixture shift]    ;
  19:L P[11:edge B1] 100mm/sec FINE Tool_Offset,PR[6:depth]    ;
  20:L P[12:edge B2] 200mm/sec FINE INC    ;
  21:L PR[20:tip dress] 500mm/sec FINE    ;
  22:L P[13:edge B3] 250mm/sec FINE    ;
  23:  LBL[90] ;
  24:J P[1:HOME] 30% FINE    ;
  25:  ! end ;
/POS
P[1:"HOME"]{
   GP1:
	UF : 1, UT : 1,
	J1=     0.000 deg,	J2=   -90.000 deg,	J3=    90.000 deg,
	J4=     0.000 deg,	J5=    90.000 deg,	J6=     0.000 deg
};
P[2:"above A"]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   400.000  mm,	Y =   150.000  mm,	Z =   500.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[3:"edge A1"]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   420.000  mm,	Y =   100.000  mm,	Z =   300.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[4:"edge A2"]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   600.000  mm,	Y =   100.000  mm,	Z =   300.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[5:"arc via"]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   680.000  mm,	Y =   160.000  mm,	Z =   300.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[6:"arc end"]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   700.000  mm,	Y =   240.000  mm,	Z =   300.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[7:"arc 2"]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   680.000  mm,	Y =   320.000  mm,	Z =   300.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[8:"arc 3"]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   600.000  mm,	Y =   380.000  mm,	Z =   300.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[9:"leave A"]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   600.000  mm,	Y =   380.000  mm,	Z =   600.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[10:"above B"]{
   GP1:
	UF : 2, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   200.000  mm,	Y =  -100.000  mm,	Z =   450.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =    90.000 deg
};
P[11:"edge B1"]{
   GP1:
	UF : 2, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   250.000  mm,	Y =  -150.000  mm,	Z =   250.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =    90.000 deg
};
P[12:"edge B2"]{
   GP1:
	UF : 2, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =     0.000  mm,	Y =    50.000  mm,	Z =     0.000  mm,
	W =     0.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[13:"edge B3"]{
   GP1:
	UF : 2, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   400.000  mm,	Y =  -150.000  mm,	Z =   250.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =    90.000 deg
};
/END
