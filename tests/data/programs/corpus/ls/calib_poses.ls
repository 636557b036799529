/PROG  CALIB_POSES
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 2310;
CREATE		= DATE 24-03-11  TIME 08:12:40;
MODIFIED	= DATE 24-03-12  TIME 14:02:16;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 13;
MEMORY_SIZE	= 2750;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,1,*,*,*;
CONTROL_CODE	= 00000000 00000000;
LOCAL_REGISTERS	= 0,0,0;
/APPL
/MN
   1:   ;
   2:  OVERRIDE=20% ;
   3:   ;
   4:  UTOOL_NUM=0 ;
   5:  UFRAME_NUM=0 ;
   6:   ;
   7:L P[1] 100mm/sec CNT100    ;
   8:L P[2] 100mm/sec CNT100    ;
   9:L P[3] 100mm/sec CNT100    ;
  10:L P[4] 100mm/sec CNT100    ;
  11:L P[5] 100mm/sec CNT100    ;
  12:L P[6] 100mm/sec CNT100    ;
  13:   ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 0, 0',
	X =   508.462  mm,	Y =   216.365  mm,	Z =  1069.177  mm,
	W =  -170.122 deg,	P =    13.106 deg,	R =   178.699 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     6.428 deg
};
P[2]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 0, 0',
	X =   519.903  mm,	Y =    91.259  mm,	Z =   908.629  mm,
	W =  -173.204 deg,	P =     9.128 deg,	R =   179.445 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     6.428 deg
};
P[3]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 0, 0',
	X =   519.495  mm,	Y =   -64.328  mm,	Z =   836.823  mm,
	W =   176.620 deg,	P =     7.273 deg,	R =   179.666 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     6.428 deg
};
P[4]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 0, 0',
	X =   507.613  mm,	Y =  -173.443  mm,	Z =   993.911  mm,
	W =   171.582 deg,	P =     9.845 deg,	R =   179.882 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     6.428 deg
};
P[5]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 0, 0',
	X =   498.777  mm,	Y =   269.400  mm,	Z =   707.331  mm,
	W =  -167.486 deg,	P =     8.130 deg,	R =  -178.132 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     6.428 deg
};
P[6]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 0, 0',
	X =   505.734  mm,	Y =  -283.363  mm,	Z =   744.683  mm,
	W =   168.529 deg,	P =     8.332 deg,	R =   176.935 deg
   GP2:
	UF : 0, UT : 0,	
	J1=     6.428 deg
};
/END
